!> Bodies that need no solving this step: unstressed and unloaded, in uniform translation
!> (no spin), free of restraints, and with no impactor node within two steps' travel of the
!> other body's bounding box.
!> Newmark advances such a body exactly by q += dt v with zero acceleration, so casca does
!> just that and leaves its parameters out of the equations (docs/method.md).
module casca_free_flight
  use casca_kinds, only: dp
  use casca_model, only: model_t, dof, follower_loaded
  use casca_contact, only: contact_t, face_reach
  use casca_obstacle, only: obstacle_point
  implicit none
  private
  public :: idle_bodies, clear_near_contact, advance_idle

contains

  !> idle(b) for every body. contact may be absent (no pairs).
  subroutine idle_bodies(model, q, qd, qdd, fext, dt, idle, contact)
    type(model_t), intent(in) :: model
    real(dp), intent(in) :: q(:), qd(:), qdd(:), fext(:), dt
    logical, intent(out) :: idle(:)
    type(contact_t), intent(in), optional :: contact
    real(dp) :: shift(3), v(3), tol
    integer :: b, n, f, l
    tol = 1e-12_dp*model%length
    do b = 1, model%nbody
      associate (bd => model%body(b))
        f = dof(bd%node_first, 1); l = dof(bd%node_last, 7)
        idle(b) = .not. any(model%fixed(f:l)) .and. all(fext(f:l) == 0) .and. all(qdd(f:l) == 0)
        idle(b) = idle(b) .and. .not. follower_loaded(model, b)
        shift = q(dof(bd%node_first, 1):dof(bd%node_first, 3)) - model%x0(:, bd%node_first)
        v = qd(dof(bd%node_first, 1):dof(bd%node_first, 3))
        do n = bd%node_first, bd%node_last
          if (.not. idle(b)) exit
          idle(b) = all(abs(q(dof(n, 1):dof(n, 3)) - model%x0(:, n) - shift) <= tol) .and. &
                    all(abs(q(dof(n, 4):dof(n, 6)) - model%v0(:, n)) <= 1e-12_dp) .and. &
                    abs(q(dof(n, 7))) <= 1e-12_dp .and. &
                    all(qd(dof(n, 1):dof(n, 3)) == v) .and. all(qd(dof(n, 4):dof(n, 7)) == 0)
        end do
      end associate
    end do
    if (present(contact)) call clear_near_contact(model, q, qd, dt, contact, idle)
  end subroutine idle_bodies

  !> Clear far(b) of the bodies in contact, or with an impactor node that could reach its
  !> target within two steps of dt; near_pair (per pair): the pairs that make them so
  subroutine clear_near_contact(model, q, qd, dt, contact, far, near_pair)
    type(model_t), intent(in) :: model
    real(dp), intent(in) :: q(:), qd(:), dt
    type(contact_t), intent(in) :: contact
    logical, intent(inout) :: far(:)
    logical, intent(out), optional :: near_pair(:)
    real(dp) :: lo(3, model%nbody), hi(3, model%nbody), speed(model%nbody), reach, x(3), nrm(3), d
    logical :: near
    integer :: b, n, k, i, j
    do b = 1, model%nbody
      lo(:, b) = huge(1._dp); hi(:, b) = -huge(1._dp); speed(b) = 0
      do n = model%body(b)%node_first, model%body(b)%node_last
        lo(:, b) = min(lo(:, b), q(dof(n, 1):dof(n, 3)))
        hi(:, b) = max(hi(:, b), q(dof(n, 1):dof(n, 3)))
        speed(b) = max(speed(b), norm2(qd(dof(n, 1):dof(n, 3))))
      end do
    end do
    if (present(near_pair)) near_pair = .false.
    do k = 1, contact%set%nact   ! bodies in contact
      i = model%node_body(contact%set%act(k)%node)
      far(i) = .false.
      j = contact%pair(2, contact%set%act(k)%pair)
      if (j > 0) far(j) = .false.
      if (present(near_pair)) near_pair(contact%set%act(k)%pair) = .true.
    end do
    do k = 1, contact%npairs  ! an impactor node that could reach the target within two steps
      i = contact%pair(1, k); j = contact%pair(2, k)
      if (present(near_pair)) then
        if (near_pair(k)) cycle
      else if (j > 0) then
        if (.not. (far(i) .or. far(j))) cycle
      else
        if (.not. far(i)) cycle
      end if
      if (j > 0) then
        reach = 2*dt*(speed(i) + speed(j)) + contact%opt%tol + face_reach(contact, model, i, j)
      else
        reach = 2*dt*(speed(i) + norm2(contact%obstacle(-j)%velocity)) + contact%opt%tol + &
                face_reach(contact, model, i, j)
      end if
      do n = model%body(i)%node_first, model%body(i)%node_last
        x = q(dof(n, 1):dof(n, 3))
        if (j > 0) then
          near = all(x <= hi(:, j) + reach) .and. all(x >= lo(:, j) - reach)
        else
          call obstacle_point(contact%obstacle(-j), contact%time, x, nrm, d)
          near = d <= reach
        end if
        if (near) then
          far(i) = .false.
          if (j > 0) far(j) = .false.
          if (present(near_pair)) near_pair(k) = .true.
          exit
        end if
      end do
    end do
  end subroutine clear_near_contact

  !> The exact Newmark step of an idle body: q += dt v, v kept, acceleration zero.
  pure subroutine advance_idle(model, idle, dt, q_before, qd_before, q, qd, qdd)
    type(model_t), intent(in) :: model
    logical, intent(in) :: idle(:)
    real(dp), intent(in) :: dt, q_before(:), qd_before(:)
    real(dp), intent(inout) :: q(:), qd(:), qdd(:)
    integer :: b, f, l
    do b = 1, model%nbody
      if (.not. idle(b)) cycle
      f = dof(model%body(b)%node_first, 1); l = dof(model%body(b)%node_last, 7)
      q(f:l) = q_before(f:l) + dt*qd_before(f:l)
      qd(f:l) = qd_before(f:l)
      qdd(f:l) = 0
    end do
  end subroutine advance_idle
end module casca_free_flight
