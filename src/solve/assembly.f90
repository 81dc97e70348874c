!> Element loop over this rank's elements: internal (and inertial) force into a full-length
!> residual summed over the ranks, and the tangent into this rank's part of MUMPS's
!> distributed input. The entry pattern is fixed at setup: each element writes its lower
!> triangle of free-parameter pairs, in the same order at every call.
module casca_assembly
  use casca_kinds, only: dp
  use casca_error, only: error_t, fatal_error
  use casca_model, only: model_t, element_dofs
  use casca_shell_element, only: shell_energy_force, ndof_elem
  use casca_mpi, only: my_rank, n_ranks, sum_all, bcast_int, is_root
  use casca_metis, only: partition_elements
  implicit none
  private
  public :: assembly_t, assembly_setup, assemble

  type :: assembly_t
    integer :: neq = 0
    integer, allocatable :: eq(:)          !< (ndof) equation number, 0 if prescribed
    integer, allocatable :: elems(:)       !< this rank's elements with unknowns
    integer, allocatable :: owned(:)       !< this rank's elements for accounting (all bodies)
    integer, allocatable :: estart(:)      !< (size(elems)+1) first entry of each element
    integer, allocatable :: pos(:)         !< element-matrix linear index of each entry
    integer, allocatable :: irn(:), jcn(:) !< equations of each entry (irn >= jcn)
    real(dp), allocatable :: a(:)          !< values
  end type assembly_t

contains

  !> Equation numbering of the free parameters (neither prescribed nor frozen), the partition
  !> of the elements that have unknowns (METIS, computed on rank 0 and broadcast so that every
  !> rank agrees; the others are dealt round for the accounting) and this rank's pattern.
  subroutine assembly_setup(model, asm, err, frozen)
    type(model_t), intent(in) :: model
    type(assembly_t), intent(out) :: asm
    type(error_t), allocatable, intent(out) :: err
    logical, intent(in), optional :: frozen(:)   !< parameters advanced without solving
    integer :: d(ndof_elem), e, k, i, j, n, ia, ib
    integer, allocatable :: owner(:), active(:), part(:)

    allocate (asm%eq(model%ndof))
    n = 0
    do i = 1, model%ndof
      asm%eq(i) = 0
      if (model%fixed(i)) cycle
      if (present(frozen)) then
        if (frozen(i)) cycle
      end if
      n = n + 1; asm%eq(i) = n
    end do
    asm%neq = n

    allocate (owner(model%nelem))
    active = pack([(e, e=1, model%nelem)], [(any(asm%eq(element_dofs(model, e)) > 0), e=1, model%nelem)])
    owner = [(mod(e, n_ranks), e=1, model%nelem)]
    if (n_ranks > 1 .and. size(active) > 0) then
      allocate (part(size(active)))
      if (is_root()) then
        call partition_elements(model%conn(:, active), model%nnode, n_ranks, part, err)
        if (allocated(err)) part = -1   ! tell the other ranks, so that none waits forever
      end if
      call bcast_int(part)
      if (part(1) < 0) then
        if (.not. allocated(err)) call fatal_error(err, 'element partition failed on rank 0')
        return
      end if
      owner(active) = part
    else if (size(active) > 0) then
      owner(active) = 0
    end if
    asm%owned = pack([(e, e=1, model%nelem)], owner == my_rank)
    asm%elems = pack(active, owner(active) == my_rank)
    allocate (asm%estart(size(asm%elems) + 1))
    ! count, then fill
    k = 0
    do i = 1, size(asm%elems)
      asm%estart(i) = k + 1
      d = element_dofs(model, asm%elems(i))
      do j = 1, ndof_elem
        ib = asm%eq(d(j)); if (ib == 0) cycle
        do n = 1, ndof_elem
          ia = asm%eq(d(n))
          if (ia >= ib) k = k + 1
        end do
      end do
    end do
    asm%estart(size(asm%elems) + 1) = k + 1
    allocate (asm%pos(k), asm%irn(k), asm%jcn(k), asm%a(k))
    k = 0
    do i = 1, size(asm%elems)
      d = element_dofs(model, asm%elems(i))
      do j = 1, ndof_elem
        ib = asm%eq(d(j)); if (ib == 0) cycle
        do n = 1, ndof_elem
          ia = asm%eq(d(n))
          if (ia < ib) cycle
          k = k + 1
          asm%pos(k) = n + ndof_elem*(j - 1); asm%irn(k) = ia; asm%jcn(k) = ib
        end do
      end do
    end do
  end subroutine assembly_setup

  !> r = f_int(q) + cm M q - M qs  (qs, cm only in dynamics), summed over ranks, and
  !> (want_k) asm%a = H + cm M. energy: strain energy of q (sum over ranks).
  subroutine assemble(model, asm, q, want_k, r, energy, cm, qs)
    type(model_t), intent(in) :: model
    type(assembly_t), intent(inout) :: asm
    real(dp), intent(in) :: q(:)
    logical, intent(in) :: want_k
    real(dp), intent(out) :: r(:), energy
    real(dp), intent(in), optional :: cm, qs(:)
    real(dp) :: qe(7, 10), fe(ndof_elem), ke(ndof_elem, ndof_elem), ue, me(20, 20), acc(3, 20)
    integer :: d(ndof_elem), i, e, b, p, l
    logical :: dynamic

    dynamic = present(cm)
    r = 0; energy = 0
    do i = 1, size(asm%elems)
      e = asm%elems(i)
      d = element_dofs(model, e)
      qe = reshape(q(d), [7, 10])
      b = model%elem_body(e)
      call shell_energy_force(model%rule, model%body(b)%thickness, model%body(b)%lam, &
                              model%body(b)%mu, model%binv(:, :, :, e), model%wdet(:, e), qe, &
                              want_k, ue, fe, ke)
      energy = energy + ue
      if (dynamic) then
        ! inertia of the vector parameters (Y^l, G^l): M (cm q - qs), tangent cm M
        me = model%emass(:, :, e)
        acc(:, 1:10) = cm*qe(1:3, :) - qs_part(1)
        acc(:, 11:20) = cm*qe(4:6, :) - qs_part(4)
        acc = matmul(acc, me)
        do l = 1, 10
          fe(7*l - 6:7*l - 4) = fe(7*l - 6:7*l - 4) + acc(:, l)
          fe(7*l - 3:7*l - 1) = fe(7*l - 3:7*l - 1) + acc(:, 10 + l)
        end do
        if (want_k) call add_mass(ke, cm*me)
      end if
      r(d) = r(d) + fe
      if (want_k) then
        do p = asm%estart(i), asm%estart(i + 1) - 1
          asm%a(p) = ke(mod(asm%pos(p) - 1, ndof_elem) + 1, (asm%pos(p) - 1)/ndof_elem + 1)
        end do
      end if
    end do
    call sum_all(r)
    call sum_all(energy)
  contains
    !> the 3 x 10 block of qs for components c..c+2 of the element's nodes
    function qs_part(c) result(v)
      integer, intent(in) :: c
      real(dp) :: v(3, 10)
      integer :: ll
      do ll = 1, 10
        v(:, ll) = qs(d(7*(ll - 1) + c):d(7*(ll - 1) + c + 2))
      end do
    end function qs_part
  end subroutine assemble

  !> ke += m (x) I3 on the (Y, G) parameters
  pure subroutine add_mass(ke, m)
    real(dp), intent(inout) :: ke(ndof_elem, ndof_elem)
    real(dp), intent(in) :: m(20, 20)
    integer :: p, q, c, ip, iq
    do q = 1, 20
      iq = 7*(mod(q - 1, 10)) + merge(0, 3, q <= 10)
      do p = 1, 20
        ip = 7*(mod(p - 1, 10)) + merge(0, 3, p <= 10)
        do c = 1, 3
          ke(ip + c, iq + c) = ke(ip + c, iq + c) + m(p, q)
        end do
      end do
    end do
  end subroutine add_mass
end module casca_assembly
