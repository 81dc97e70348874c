!> Time stepping (thesis section 3.2: Newmark; or generalized-alpha, casca_time_scheme) with
!> Newton at every step (statics: casca_statics). The mass is constant, so the inertia enters
!> the residual as M (cm q - qs).
module casca_newmark
  use casca_kinds, only: dp
  use casca_error, only: error_t, fatal_error
  use casca_model, only: model_t
  use casca_assembly, only: assembly_t
  use casca_linear_system, only: linear_system_t
  use casca_newton, only: newton_opts_t, newton_report_t, newton_solve
  use casca_contact, only: contact_t, constraint_t, holds, set_restore
  use casca_contact_correction, only: contact_correction, add_impulses
  use casca_contact_projection, only: positions
  use casca_contact_friction, only: friction_step_done
  use casca_contact_active_set, only: contact_step_start
  use casca_contact_rows, only: add_step_impulse, contact_nrows, contact_force_points, pair_forces
  use casca_timers, only: timer_start, timer_stop, t_contact
  use casca_time_scheme, only: scheme_t
  implicit none
  private
  public :: state_t, newmark_step

  type :: state_t
    real(dp) :: t = 0
    integer :: step = 0
    real(dp), allocatable :: q(:), qd(:), qdd(:)
    !> the last step's length and start acceleration (scheme_t's moved_start) where no
    !> contact was active at its start or end; 0: none (a contact's force jumps, and its
    !> acceleration's change is no rate)
    real(dp) :: h_last = 0
    real(dp), allocatable :: qdd_last(:)
  end type state_t

contains

  !> One step s -> s+1 with external load fext (dead). On failure st and the contact's
  !> active set are unchanged.
  !> A contact released in the step would still push through the step's start
  !> acceleration (its force acts with weight 1 - gamma, 1/2 - beta over the step), which is
  !> how the trapezoidal rule gains 1/2 p g of energy at every release. Such a step is taken
  !> again from the start acceleration without the released contacts' net force,
  !> a + M^-1 C_R^T (lambda_R - mu_R): the force of a contact ends when it opens. With
  !> Newmark's gamma >= 1 (the thesis' 1.5) that leftover acts backwards and only dissipates:
  !> the step is not taken again. Generalized-alpha's multiplier is an alpha-level force, whose
  !> share of the end acceleration is lambda / (1 - alpha_m) (a flat plate landing on another
  !> made 3.9% of its energy in the step that released it with rho_inf 0.8, 2.9% with 0,
  !> whatever dt, when the start acceleration kept half or more of that share): the step is
  !> taken again for every rho_inf.
  subroutine newmark_step(model, asm, ls, nm, fext, opts, st, rep, err, contact)
    type(model_t), intent(in) :: model
    type(assembly_t), intent(inout) :: asm
    type(linear_system_t), intent(inout) :: ls
    type(scheme_t), intent(in) :: nm
    real(dp), intent(in) :: fext(:)
    type(newton_opts_t), intent(in) :: opts
    type(state_t), intent(inout) :: st
    type(newton_report_t), intent(out) :: rep
    type(error_t), allocatable, intent(out) :: err
    type(contact_t), intent(inout), optional :: contact
    real(dp), allocatable :: q(:), qd(:), qdd(:), a0(:), nu(:), loss(:), f_end(:, :)
    type(constraint_t), allocatable :: before(:), released(:)
    real(dp) :: dt
    integer :: k, iters
    logical :: compliant, free

    dt = nm%dt
    compliant = .false.
    if (present(contact)) compliant = contact%opt%compliant
    allocate (a0, source=st%qdd)   ! (explicitly: gcc 12 warned of the descriptor)
    free = .true.
    if (present(contact)) free = contact%set%nact == 0
    if (free .and. st%h_last > 0) then
      call nm%moved_start(st%h_last, st%qdd_last, a0)
      if (present(contact)) call nm%moved_share(st%h_last, contact%carry)
    end if
    allocate (q(size(st%q)), qd(size(st%q)), qdd(size(st%q)))
    if (present(contact)) then
      call contact_force_points(contact, model, nm%alpha_f, st%q)   ! (as the last step left them: restarts too)
      before = contact%set%act(1:contact%set%nact)
      contact%time = st%t + dt   ! (the obstacles where they are at the end of the step)
      contact%x_start = positions(model, st%q); contact%dt = dt
      call contact_step_start(contact)
      contact%opt%alpha_f = nm%alpha_f
      contact%set%act(1:contact%set%nact)%g0 = contact%set%act(1:contact%set%nact)%gap
      contact%g_start = positions(model, st%q, fibres=.true.)   ! (friction's slip)
    end if
    released = [constraint_t ::]
    call attempt(warm=.false.)
    if (allocated(err)) then   ! (newton restores the set itself; the correction may not)
      if (present(contact)) call set_restore(contact%set, before)
      return
    end if
    ! (a compliant contact's force falls to zero with its gap before it is released)
    if (present(contact) .and. nm%drops_released() .and. .not. compliant) then
      do k = 1, size(before)
        if (.not. holds(contact%set, before(k)%node, before(k)%pair)) released = [released, before(k)]
      end do
      if (size(released) > 0) then
        call timer_start(t_contact)
        call add_impulses(ls%mass, released, model, a0, err, 1/(1 - nm%alpha_m))
        call timer_stop(t_contact)
        if (allocated(err)) return
        iters = rep%iters
        call attempt(warm=.true.)
        if (allocated(err)) then   ! (the state is as it was: the step is cut)
          call set_restore(contact%set, before)
          return
        end if
        rep%iters = rep%iters + iters
      end if
    end if
    if (present(contact)) then   ! (before friction turns its slip directions)
      call add_step_impulse(contact, nm, released, nu, f_end, loss)
      call friction_step_done(contact, nm, before)
    end if
    st%h_last = 0
    if (present(contact)) free = free .and. contact%set%nact == 0
    if (free) then
      st%h_last = dt; st%qdd_last = a0
    end if
    st%q = q; st%qd = qd; st%qdd = qdd
    st%t = st%t + dt
    st%step = st%step + 1
  contains
    !> the step from (st%q, st%qd, a0): q, qd, qdd. warm: Newton starts from the last
    !> attempt's q and active set, which a0 changed by the released contacts' force alone
    !> leaves close (from the predictor and the start's set again, a pressurised ball
    !> flattening on a wall, whose contacts open every step, took each step twice over)
    subroutine attempt(warm)
      logical, intent(in) :: warm
      real(dp), allocatable :: qs(:)
      real(dp) :: cm
      allocate (qs(size(st%q)))
      call nm%inertia(st%q, st%qd, a0, cm, qs)
      ! (the first step's start acceleration is the loads' M^-1 F, not a step's: spiky under
      ! a point load, and predicted from it Newton failed a thin strip's first step)
      if (.not. warm) call nm%predictor(st%q, st%qd, merge(a0, 0*a0, st%step > 0), q)
      where (model%fixed) q = st%q
      call newton_solve(model, asm, ls, q, fext, opts, rep, err, cm, qs, contact, st%q, nm%alpha_f)
      if (.not. allocated(err) .and. .not. rep%converged) &
        call fatal_error(err, 'Newton did not converge')
      if (allocated(err)) return
      call nm%update(st%q, st%qd, a0, q, qd, qdd)
      if (present(contact)) then   ! (on failure the state is left as it was)
        call timer_start(t_contact)
        ! the forces as they acted (at the internal force's configuration), then the
        ! correction's impulses where the step ends
        call contact_force_points(contact, model, nm%alpha_f, q, st%q)
        f_end = pair_forces(contact)
        call contact_force_points(contact, model, nm%alpha_f, q)
        if (allocated(nu)) deallocate (nu, loss)
        allocate (nu(contact_nrows(contact)), loss(contact_nrows(contact)))
        nu = 0; loss = 0   ! (a compliant contact's velocities are the scheme's own: no correction)
        if (.not. compliant) call contact_correction(ls%mass, ls%correction, contact, model, qd, qdd, err, &
                                                     nu, loss)
        call timer_stop(t_contact)
        if (allocated(err)) return
      end if
      where (model%fixed)
        qd = 0; qdd = 0
      end where
    end subroutine attempt
  end subroutine newmark_step
end module casca_newmark
