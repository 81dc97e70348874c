!> Diagnostics of a contact state (history and VTU), from a probe: the same geometry with no
!> constraint and its own tolerance, so that detection itself measures the penetration.
module casca_contact_probes
  use casca_kinds, only: dp
  use casca_model, only: model_t
  use casca_contact, only: contact_t, search_radius, holds
  use casca_contact_active_set, only: contact_update
  implicit none
  private
  public :: contact_penetration, contact_signed_distance

contains

  !> Deepest penetration of the impactor nodes that carry no constraint (their gap) or are
  !> held where they were (constraint_t%hold), and largest |gap| of those that carry one.
  subroutine contact_penetration(c, model, q, free_pen, max_gap, deepest)
    type(contact_t), intent(in) :: c
    type(model_t), intent(in) :: model
    real(dp), intent(in) :: q(:)
    real(dp), intent(out) :: free_pen, max_gap
    integer, intent(out), optional :: deepest   !< the node that penetrates free_pen (0: none)
    type(contact_t) :: probe
    integer :: added, k, node
    ! a probe with no active constraint and zero tolerance detects every penetrating node
    call new_probe(c, 0._dp, probe)
    call contact_update(probe, model, q, .true., added, .false.)
    free_pen = 0; node = 0
    do k = 1, probe%set%nact
      if (holds(c%set, probe%set%act(k)%node, probe%set%act(k)%pair)) cycle
      if (-probe%set%act(k)%gap > free_pen) then
        free_pen = -probe%set%act(k)%gap; node = probe%set%act(k)%node
      end if
    end do
    do k = 1, c%set%nact   ! (held, not pushed out)
      if (-c%set%act(k)%hold > free_pen) then
        free_pen = -c%set%act(k)%hold; node = c%set%act(k)%node
      end if
    end do
    if (present(deepest)) deepest = node
    max_gap = 0
    if (c%set%nact > 0) max_gap = maxval(abs(c%set%act(1:c%set%nact)%gap))
  end subroutine contact_penetration

  !> Gap of every impactor node to its target between the surfaces in contact (faces or
  !> mid-surfaces): the search radius where farther, 0 for nodes that impact nothing.
  subroutine contact_signed_distance(c, model, q, sd)
    type(contact_t), intent(in) :: c
    type(model_t), intent(in) :: model
    real(dp), intent(in) :: q(:)
    real(dp), intent(out) :: sd(:)
    type(contact_t) :: probe
    integer :: added, k, ip, b
    sd = 0
    do ip = 1, c%npairs
      b = c%pair(1, ip)
      sd(model%body(b)%node_first:model%body(b)%node_last) = search_radius(c, model, b, c%pair(2, ip))
    end do
    ! every node within reach, penetrating or not: a probe that takes any gap
    call new_probe(c, -huge(1._dp), probe)
    call contact_update(probe, model, q, .true., added, .false.)
    do k = 1, probe%set%nact
      sd(probe%set%act(k)%node) = min(sd(probe%set%act(k)%node), probe%set%act(k)%gap)
    end do
  end subroutine contact_signed_distance

  !> The geometry of c with no constraint and tolerance tol.
  subroutine new_probe(c, tol, probe)
    type(contact_t), intent(in) :: c
    real(dp), intent(in) :: tol
    type(contact_t), intent(out) :: probe
    probe = c
    probe%set%nact = 0
    probe%set%changes = 0
    probe%geo%grid_ok = .false.
    probe%opt%tol = tol
    probe%opt%probe = .true.
  end subroutine new_probe
end module casca_contact_probes
