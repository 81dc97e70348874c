!> Newmark time stepping (thesis section 3.2) with Newton at every step, and load-stepped
!> statics. The mass is constant, so the inertia enters the residual as M (q/(beta dt^2) - Q_s).
module casca_newmark
  use casca_kinds, only: dp
  use casca_error, only: error_t, fatal_error
  use casca_model, only: model_t
  use casca_assembly, only: assembly_t
  use casca_linear_system, only: linear_system_t
  use casca_newton, only: newton_opts_t, newton_report_t, newton_solve
  use casca_contact, only: contact_t, contact_persistency
  implicit none
  private
  public :: state_t, newmark_t, newmark_step, static_solve

  type :: state_t
    real(dp) :: t = 0
    integer :: step = 0
    real(dp), allocatable :: q(:), qd(:), qdd(:)
  end type state_t

  type :: newmark_t
    real(dp) :: beta = 1.0_dp, gamma = 1.5_dp   !< the thesis' dissipative choice for impact
    real(dp) :: dt = 0
  end type newmark_t

contains

  !> One step s -> s+1 with external load fext (dead). On failure st and the contact's
  !> active set are unchanged.
  subroutine newmark_step(model, asm, ls, nm, fext, opts, st, rep, err, contact)
    type(model_t), intent(in) :: model
    type(assembly_t), intent(inout) :: asm
    type(linear_system_t), intent(inout) :: ls
    type(newmark_t), intent(in) :: nm
    real(dp), intent(in) :: fext(:)
    type(newton_opts_t), intent(in) :: opts
    type(state_t), intent(inout) :: st
    type(newton_report_t), intent(out) :: rep
    type(error_t), allocatable, intent(out) :: err
    type(contact_t), intent(inout), optional :: contact
    real(dp), allocatable :: qs(:), rs(:), q(:)
    real(dp) :: b, dt, g

    b = nm%beta; g = nm%gamma; dt = nm%dt
    allocate (qs, rs, q, mold=st%q)   ! (not on assignment: gfortran warns, falsely)
    qs = st%q/(b*dt*dt) + st%qd/(b*dt) + (0.5_dp/b - 1)*st%qdd
    rs = st%qd + dt*(1 - g)*st%qdd
    ! predictor: the step taken with zero new acceleration
    q = st%q + dt*st%qd + dt*dt*(0.5_dp - b)*st%qdd
    where (model%fixed) q = st%q
    call newton_solve(model, asm, ls, q, fext, opts, rep, err, 1/(b*dt*dt), qs, contact)
    if (.not. allocated(err) .and. .not. rep%converged) &
      call fatal_error(err, 'Newton did not converge')
    if (allocated(err)) return
    st%q = q
    st%qdd = q/(b*dt*dt) - qs
    st%qd = rs + g*dt*st%qdd
    if (present(contact)) call contact_persistency(contact, model, st%qd, st%qdd)
    where (model%fixed)
      st%qd = 0; st%qdd = 0
    end where
    st%t = st%t + dt
    st%step = st%step + 1
  end subroutine newmark_step

  !> Statics: the dead load fext scaled from factor from to factor to, in one increment if
  !> Newton converges, else in halved increments (at most max_cuts halvings), growing back
  !> after easy ones. q holds the start and the result; on failure it is the last converged
  !> state and err says at which factor.
  subroutine static_solve(model, asm, ls, fext, from, to, max_cuts, opts, q, rep, err, contact)
    type(model_t), intent(in) :: model
    type(assembly_t), intent(inout) :: asm
    type(linear_system_t), intent(inout) :: ls
    real(dp), intent(in) :: fext(:), from, to
    integer, intent(in) :: max_cuts
    type(newton_opts_t), intent(in) :: opts
    real(dp), intent(inout) :: q(:)
    type(newton_report_t), intent(out) :: rep
    type(error_t), allocatable, intent(out) :: err
    type(contact_t), intent(inout), optional :: contact
    real(dp) :: at, step
    integer :: level, iters
    character(len=120) :: msg
    at = from; level = 0; iters = 0
    do while (at < to - 1e-12_dp*abs(to - from))
      step = min((to - from)/2**level, to - at)
      call newton_solve(model, asm, ls, q, fext*(at + step), opts, rep, err, contact=contact)
      if (.not. allocated(err) .and. .not. rep%converged) call fatal_error(err, 'not converged')
      if (allocated(err)) then
        if (level >= max_cuts) then
          write (msg, '(a,g0.6,a,i0,a)') 'static Newton did not converge at load factor ', &
            at + step, ' (after ', level, ' halvings of the load step): '
          err%message = trim(msg)//err%message
          return
        end if
        level = level + 1   ! q is unchanged: half the increment
        deallocate (err)
        cycle
      end if
      iters = iters + rep%iters
      at = at + step
      if (level > 0 .and. rep%iters <= 4) level = level - 1   ! Newton is at ease: grow back
    end do
    rep%iters = iters
  end subroutine static_solve
end module casca_newmark
