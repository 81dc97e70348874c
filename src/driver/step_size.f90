!> What the error-controlled step (casca_run's step_length) asks of the contact: the
!> predicted time of first contact, at which a step is ended so that the onset is not
!> stepped over.
module casca_step_size
  use casca_kinds, only: dp
  use casca_model, only: model_t
  use casca_contact, only: contact_t
  use casca_pair_gaps, only: pair_gap_t, pair_gaps_at
  use casca_free_flight, only: clear_near_contact
  implicit none
  private
  public :: time_to_contact

contains

  !> The earliest time to contact of the pairs within dt (each node's straight path,
  !> casca_pair_gaps) when no constraint is active and a
  !> body could reach another within two steps of dt; huge when none is predicted. Moving
  !> obstacles are left out (pair_gaps places them where they start).
  real(dp) function time_to_contact(c, model, q, qd, dt) result(t)
    type(contact_t), intent(in) :: c
    type(model_t), intent(in) :: model
    real(dp), intent(in) :: q(:), qd(:), dt
    type(pair_gap_t), allocatable :: pg(:)
    logical :: far(model%nbody)
    integer :: k
    t = huge(1._dp)
    if (c%set%nact > 0) return
    if (any([(norm2(c%obstacle(k)%velocity) > 0, k=1, size(c%obstacle))])) return
    far = .true.
    call clear_near_contact(model, q, qd, dt, c, far)
    if (all(far)) return
    pg = pair_gaps_at(c, model, q, qd, dt)
    do k = 1, size(pg)
      if (pg(k)%time >= 0) t = min(t, pg(k)%time)
    end do
  end function time_to_contact
end module casca_step_size
