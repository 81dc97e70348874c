!> Newmark time stepping (thesis section 3.2) with Newton at every step, and load-stepped
!> statics. The mass is constant, so the inertia enters the residual as M (q/(beta dt^2) - Q_s).
module casca_newmark
  use casca_kinds, only: dp
  use casca_error, only: error_t, fatal_error
  use casca_model, only: model_t
  use casca_assembly, only: assembly_t, nblocks
  use casca_mumps_solver, only: sparse_solver_t
  use casca_newton, only: newton_opts_t, newton_report_t, newton_solve
  use casca_contact, only: contact_t, constraint_t, contact_persistency
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
  subroutine newmark_step(model, asm, solver, nm, fext, opts, st, rep, err, contact)
    type(model_t), intent(in) :: model
    type(assembly_t), intent(inout) :: asm
    type(sparse_solver_t), intent(inout) :: solver(nblocks)
    type(newmark_t), intent(in) :: nm
    real(dp), intent(in) :: fext(:)
    type(newton_opts_t), intent(in) :: opts
    type(state_t), intent(inout) :: st
    type(newton_report_t), intent(out) :: rep
    type(error_t), allocatable, intent(out) :: err
    type(contact_t), intent(inout), optional :: contact
    real(dp), allocatable :: qs(:), rs(:), q(:)
    real(dp) :: b, dt, g
    type(constraint_t), allocatable :: saved(:)   ! the active set, kept for a failed step

    b = nm%beta; g = nm%gamma; dt = nm%dt
    allocate (qs, rs, q, mold=st%q)   ! (not on assignment: gfortran warns, falsely)
    qs = st%q/(b*dt*dt) + st%qd/(b*dt) + (0.5_dp/b - 1)*st%qdd
    rs = st%qd + dt*(1 - g)*st%qdd
    ! predictor: the step taken with zero new acceleration
    q = st%q + dt*st%qd + dt*dt*(0.5_dp - b)*st%qdd
    where (model%fixed) q = st%q
    if (present(contact)) then
      saved = contact%act(1:contact%nact)
      call newton_solve(model, asm, solver, q, fext, opts, rep, err, 1/(b*dt*dt), qs, contact)
    else
      call newton_solve(model, asm, solver, q, fext, opts, rep, err, 1/(b*dt*dt), qs)
    end if
    if (.not. allocated(err) .and. .not. rep%converged) &
      call fatal_error(err, 'Newton did not converge')
    if (allocated(err)) then
      if (present(contact)) then
        contact%nact = size(saved)
        contact%act(1:size(saved)) = saved
      end if
      return
    end if
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

  !> Statics in nsteps equal load increments of fext; q holds the start and the result.
  subroutine static_solve(model, asm, solver, fext, nsteps, opts, q, rep, err, contact)
    type(model_t), intent(in) :: model
    type(assembly_t), intent(inout) :: asm
    type(sparse_solver_t), intent(inout) :: solver(nblocks)
    real(dp), intent(in) :: fext(:)
    integer, intent(in) :: nsteps
    type(newton_opts_t), intent(in) :: opts
    real(dp), intent(inout) :: q(:)
    type(newton_report_t), intent(out) :: rep
    type(error_t), allocatable, intent(out) :: err
    type(contact_t), intent(inout), optional :: contact
    integer :: i
    do i = 1, nsteps
      call newton_solve(model, asm, solver, q, fext*(real(i, dp)/nsteps), opts, rep, err, &
                        contact=contact)
      if (allocated(err)) return
      if (.not. rep%converged) then
        call fatal_error(err, 'static Newton did not converge')
        return
      end if
    end do
  end subroutine static_solve
end module casca_newmark
