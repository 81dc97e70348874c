!> Load-stepped statics, with a viscous path to an equilibrium that only contact holds.
!>
!> A body held by contact alone (a plate laid on a floor, a ball resting in a cup) has no
!> stiffness against its rigid motions until its contacts close, so Newton's tangent is
!> singular and no halving of the load cures it. A load increment Newton fails is taken
!> again by pseudo-transient continuation (Kelley & Keyes 1998), the idea of Abaqus/Standard's
!> automatic stabilisation: stages with a stabilising force c M (q - q_n), q_n the state the
!> stage starts from, as damped pseudo-time steps. The bodies move towards their contacts and
!> settle on them. Each stage that converges starts the next from its state with c ten times
!> lower (longer pseudo-steps); one that does not is taken again with c ten times higher.
!> When the stabilising force is within Newton's own force tolerance the bodies have stopped:
!> a last Newton solve without it gives the equilibrium exactly where the equilibrium is
!> regular, and where it is not (a frictionless body free to slide under no sideways load)
!> the stabilised state stands, in equilibrium within the tolerance. That solve is tried
!> earlier too, from a stage Newton took easily while the force fell: a shell settling on
!> its far branch after a snap-through does so slowly at the c its snap needed. A body that
!> nothing holds against its load never stops (the damping goes on carrying a part of the
!> load, and the body goes further than the scene's size), and is an error naming it.
module casca_statics
  use casca_kinds, only: dp
  use casca_strings, only: rtoa, itoa
  use casca_error, only: error_t, fatal_error
  use casca_model, only: model_t, element_dofs
  use casca_mpi, only: sum_all
  use casca_shell_element, only: ndof_node
  use casca_assembly, only: assembly_t
  use casca_linear_system, only: linear_system_t
  use casca_newton, only: newton_opts_t, newton_report_t, newton_solve, contraction
  use casca_contact, only: contact_t, constraint_t, set_restore
  use casca_contact_rows, only: contact_newton_nrows
  use casca_contact_projection, only: positions
  use casca_contact_friction, only: friction_step_done
  use casca_time_scheme, only: newmark_scheme
  use casca_stop_request, only: stop_requested
  implicit none
  private
  public :: static_solve, unloaded_inertia

  integer, parameter :: max_stages = 100     !< stabilised stages of one load step
  real(dp), parameter :: stage_factor = 10    !< c's change from stage to stage
  real(dp), parameter :: max_damping = 1e4    !< c at most this times the first stage's
  real(dp), parameter :: unheld_part = 1e-3   !< of the scene's force the damping carries
  integer, parameter :: probe_levels = 2      !< halvings tried before the stabilised path

contains

  !> Statics: the dead load fext scaled from factor from to factor to, in one increment if
  !> Newton converges, else stabilised (once per call), else in halved increments (at most
  !> max_cuts halvings), growing back after easy ones. Where Newton ran out of iterations
  !> (the increment too long for it) the half is tried first, then the quarter, and the
  !> stabilised path only if they fail too, then on what is left of the increment: Sze's
  !> cantilever rolled up by an end moment in 10 load steps, Newton needing 24 iterations a
  !> whole step, took the stabilised path in all ten (13 s), where halves take 13 to 15
  !> iterations; a thinner strip rolled 1.5 turns, 5,762 iterations in all, where quarters
  !> take 16 (1,041 in all); a snap-through, which no halving passes, spends about a
  !> quarter more on the failed tries (Sze's pinched cylinder: 1,312 for 1,057). q holds
  !> the start and the result; on failure it is the last converged state and err says at
  !> which factor. A stop signal ends it between Newton solves with err set and q anywhere:
  !> the caller abandons the load step (stop_pending).
  subroutine static_solve(model, asm, ls, fext, from, to, max_cuts, opts, q, rep, err, &
                          stabilised, contact)
    type(model_t), intent(in) :: model
    type(assembly_t), intent(inout) :: asm
    type(linear_system_t), intent(inout) :: ls
    real(dp), intent(in) :: fext(:), from, to
    integer, intent(in) :: max_cuts
    type(newton_opts_t), intent(in) :: opts
    real(dp), intent(inout) :: q(:)
    type(newton_report_t), intent(out) :: rep
    type(error_t), allocatable, intent(out) :: err
    integer, intent(out) :: stabilised   !< increments that took the stabilised path
    type(contact_t), intent(inout), optional :: contact
    real(dp) :: at, step
    integer :: level, iters, k
    logical :: unheld
    logical :: probed   !< halves were tried first (doc above)
    integer :: tries   !< stabilised solves tried (module comment)
    type(constraint_t), allocatable :: before(:)
    character(len=:), allocatable :: damped   !< how the stabilised path failed ('': it did not)
    at = from; level = 0; iters = 0; unheld = .false.; stabilised = 0; tries = 0; probed = .false.; damped = ''
    if (present(contact)) contact%opt%stick_at_touch = .true.
    do while (at < to - 1e-12_dp*abs(to - from))
      if (stop_pending(err)) return
      step = min((to - from)/2**level, to - at)
      if (present(contact)) then   ! (friction's slip is over the load increment)
        do k = 1, contact%set%nact
          contact%set%act(k)%u0 = 0
        end do
        before = contact%set%act(1:contact%set%nact)
        contact%x_start = positions(model, q); contact%g_start = positions(model, q, fibres=.true.)
      end if
      call newton_solve(model, asm, ls, q, fext*(at + step), opts, rep, err, contact=contact, &
                        load_factor=at + step)   ! the pressures scaled too (issue 17)
      if (.not. allocated(err) .and. .not. rep%converged) call fatal_error(err, 'not converged')
      if (allocated(err) .and. opts%linear) then   ! (one solve; a singular K0 stays singular)
        err%message = 'the linear solve failed (K0 singular: a body free to move, or a mechanism?): '// &
                      err%message
        return
      end if
      ! (Newton out of iterations far from equilibrium, or converging: the half and quarter
      ! first, the levels before a stabilised solve being these; within its force tolerance,
      ! its increments not shrinking, a free motion no half cures: a sphere under pressure)
      if (allocated(err) .and. tries == 0 .and. level < probe_levels .and. rep%iters >= opts%max_iter &
          .and. (rep%residual > opts%force_tol .or. converging(rep))) then
        probed = .true.; level = level + 1; iters = iters + rep%iters
        deallocate (err)
        cycle
      end if
      if (allocated(err) .and. probed .and. tries == 0) then   ! (what is left, as below)
        level = 0; step = to - at
      end if
      ! (stabilised on the step and its first half only: a buckled sphere spent 55 s more at
      ! every halving; a hemisphere whose whole load was too far needed the half's)
      if (allocated(err) .and. (tries == 0 .or. (tries == 1 .and. level == 1))) then
        iters = iters + rep%iters; tries = tries + 1
        deallocate (err)
        call stabilised_solve(model, asm, ls, fext*(at + step), at + step, opts, q, rep, err, &
                              unheld, contact)
        if (.not. allocated(err)) stabilised = stabilised + 1
        if (allocated(err) .and. .not. unheld) damped = '; '//err%message   ! (told at the end)
      end if
      iters = iters + rep%iters
      if (allocated(err)) then
        if (level >= max_cuts .or. unheld) then   ! (a smaller load does not hold a body)
          err%message = 'static Newton did not converge at load factor '//rtoa(at + step)//' (after '// &
                        itoa(level)//' halvings of the load step): '//err%message//damped
          return
        end if
        level = level + 1   ! q is unchanged: half the increment
        deallocate (err)
        cycle
      end if
      if (rep%factored_at <= 1 .and. at + step >= to - 1e-12_dp*abs(to - from) .and. .not. opts%linear) &
        call fresh_inertia(model, asm, ls, fext*to, to, opts, q, rep, iters, contact)   ! (this state's)
      if (present(contact)) call friction_step_done(contact, newmark_scheme(0._dp, 1._dp), before, &
                                                    static=.true.)   ! (s kept: friction_step_done)
      at = at + step
      if (level > 0 .and. rep%iters <= 4) level = level - 1   ! Newton is at ease: grow back
    end do
    rep%iters = iters
  end subroutine static_solve

  !> A stop signal came (stop_request): err says so. Asked between Newton solves, as a load
  !> step's halvings and up to max_stages stabilised stages ran 190 s past a batch system's
  !> SIGTERM (validator S33, F4); the caller keeps the last converged load step.
  logical function stop_pending(err)
    type(error_t), allocatable, intent(inout) :: err
    stop_pending = stop_requested() > 0
    if (stop_pending) call fatal_error(err, 'a stop signal came during the load step')
  end function stop_pending

  !> The last increment a tenth of the one before or less (Newton near its end)
  logical pure function converging(rep)
    type(newton_report_t), intent(in) :: rep
    converging = .false.
    if (rep%nincr >= 2) converging = contraction(rep) < 0.1_dp
  end function converging

  !> The inertia of the tangent at the converged state q (rep%neg_pivots), where the step
  !> converged on factors made at its increment's start or kept from an earlier state: one
  !> Newton solve with fresh factors, which starts within its tolerance. Such factors would
  !> hide a buckling point: a column at 1.5 times Euler's load took every step on the
  !> unloaded state's factors, and in one load step on those its first iteration made.
  subroutine fresh_inertia(model, asm, ls, fext, factor, opts, q, rep, iters, contact)
    type(model_t), intent(in) :: model
    type(assembly_t), intent(inout) :: asm
    type(linear_system_t), intent(inout) :: ls
    real(dp), intent(in) :: fext(:), factor
    type(newton_opts_t), intent(in) :: opts
    real(dp), intent(inout) :: q(:)
    type(newton_report_t), intent(inout) :: rep
    integer, intent(inout) :: iters   !< the load step's Newton iterations, this solve's added
    type(contact_t), intent(inout), optional :: contact
    type(newton_opts_t) :: fresh
    type(newton_report_t) :: check
    type(error_t), allocatable :: err
    fresh = opts; fresh%reuse = .false.
    call newton_solve(model, asm, ls, q, fext, fresh, check, err, contact=contact, load_factor=factor)
    iters = iters + check%iters
    if (.not. allocated(err)) rep%neg_pivots = check%neg_pivots   ! (else q as it was)
  end subroutine fresh_inertia

  !> The negative pivots of the stiffness at the unloaded state q (its contact rows' pivots left
  !> out; -1 where the solve fails): one linear solve K(q) dq = f on copies (a Newton
  !> iteration with fresh factors that any residual passes: at load factor 0 no force
  !> judges it), the factors dropped after it so that the first load step starts as it
  !> would have. The first load step's inertia is judged against it (watch_stability): a
  !> column past Euler's load in its first step was not told (validator S33, F1).
  integer function unloaded_inertia(model, asm, ls, fext, opts, q, contact) result(neg)
    type(model_t), intent(in) :: model
    type(assembly_t), intent(inout) :: asm
    type(linear_system_t), intent(inout) :: ls
    real(dp), intent(in) :: fext(:), q(:)
    type(newton_opts_t), intent(in) :: opts
    type(contact_t), intent(in), optional :: contact
    type(contact_t), allocatable :: c
    type(newton_opts_t) :: once
    type(newton_report_t) :: rep
    type(error_t), allocatable :: err
    real(dp), allocatable :: q1(:)
    once = opts; once%reuse = .false.; once%max_iter = 1
    once%tol = 1e100_dp; once%force_tol = 1e100_dp   ! (as a linear analysis's)
    q1 = q
    if (present(contact)) then
      c = contact
      call newton_solve(model, asm, ls, q1, fext, once, rep, err, contact=c, load_factor=1._dp)
      neg = rep%neg_pivots - contact_newton_nrows(c)
    else
      call newton_solve(model, asm, ls, q1, fext, once, rep, err, load_factor=1._dp)
      neg = rep%neg_pivots
    end if
    if (allocated(err) .or. .not. rep%converged) neg = -1
    call ls%drop_factors()
  end function unloaded_inertia

  !> One load step through stabilised stages (module comment); unheld: a body kept moving.
  !> On failure q and the contact's active set are as they were at entry.
  subroutine stabilised_solve(model, asm, ls, fext, factor, opts, q, rep, err, unheld, contact)
    type(model_t), intent(in) :: model
    type(assembly_t), intent(inout) :: asm
    type(linear_system_t), intent(inout) :: ls
    real(dp), intent(in) :: fext(:), factor
    type(newton_opts_t), intent(in) :: opts
    real(dp), intent(inout) :: q(:)
    type(newton_report_t), intent(out) :: rep
    type(error_t), allocatable, intent(out) :: err
    logical, intent(out) :: unheld
    type(contact_t), intent(inout), optional :: contact
    real(dp), allocatable :: q_entry(:), q_n(:)
    type(constraint_t), allocatable :: act_entry(:)
    type(newton_opts_t) :: fresh
    real(dp) :: c, c0, c_fail, fs, travel, fs_before, fs_tried
    integer :: stage, iters, moving, k
    logical :: settled, stopped
    character(len=300) :: msg

    allocate (q_entry, source=q)   ! (explicitly: gcc 12 warned of the descriptor)
    q_n = q
    if (present(contact)) act_entry = contact%set%act(1:contact%set%nact)
    c0 = stabilisation(model); c = c0
    fresh = opts
    fresh%reuse = .false.   ! (kept factors are of another c, or of the singular tangent)
    fresh%max_iter = min(opts%max_iter, 10)   ! (a stage that struggles: shorter pseudo-steps)
    iters = 0; moving = 0; fs = 0; c_fail = 0; unheld = .false.
    fs_before = 0; fs_tried = huge(1._dp)
    do stage = 1, max_stages
      if (stop_pending(err)) return   ! (q and the contacts as they are: static_solve's comment)
      call newton_solve(model, asm, ls, q, fext, fresh, rep, err, cm=c, qs=c*q_n, &
                        contact=contact, load_factor=factor)
      iters = iters + rep%iters
      if (.not. allocated(err) .and. .not. rep%converged) call fatal_error(err, 'not converged')
      if (allocated(err)) then   ! a shorter pseudo-step, and none as long again
        c_fail = max(c_fail, c)
        c = c*stage_factor
        if (c > max_damping*c0) exit
        deallocate (err)
        cycle
      end if
      call stabilising_force(model, asm, q, q_n, c, fs, moving)
      stopped = fs <= opts%force_tol*rep%force_scale
      fs = fs/rep%force_scale
      ! (also before the bodies stop: settling after a snap-through, at the c that a failed
      ! stage left, the force falls by a few per cent a stage while the equilibrium is near;
      ! tried again once the force has halved since the last try, or after it rose again)
      if (stopped .or. (rep%iters <= 3 .and. fs < fs_before .and. fs <= fs_tried/2)) then
        fs_tried = fs
        call unstabilised(iters, settled)   ! (where not, the stopped state stands)
        if (settled .or. stopped) then
          rep%iters = iters
          return
        end if
      end if
      if (fs > fs_before) fs_tried = huge(1._dp)   ! (rising: a fall after it settles anew)
      fs_before = fs
      q_n = q; c = max(c/stage_factor, 2*c_fail)
    end do
    ! (stages converged, the damping still carries a part of the scene's force, and a body
    ! went further than the scene's size: it holds what nothing else does; a body settling
    ! slowly, or snapping through, leaves it a vanishing part or stays within the scene)
    travel = 0
    do k = 1, 3   ! (the mid-surface's positions)
      travel = max(travel, maxval(abs(q(k::ndof_node) - q_entry(k::ndof_node))))
    end do
    if (moving > 0 .and. fs > unheld_part .and. travel > model%length) then
      if (allocated(err)) deallocate (err)
      unheld = .true.
      write (msg, '(3a,es9.2,a,es9.2,a)') 'no equilibrium: body ''', model%body(moving)%name, &
        ''' keeps moving under the load (', travel, ' m in pseudo-time steps, the damping &
        &still carrying ', fs, ' of the scene force); is every body held against every &
        &load, by restraints or contacts?'
      call fatal_error(err, trim(msg))
    else
      if (.not. allocated(err)) call fatal_error(err, 'the damped bodies did not come to rest (past &
        &a limit load, where a shell buckles or snaps through, load control has no equilibrium near)')
      err%message = 'stabilised: '//err%message
    end if
    rep%iters = iters
    q = q_entry
    if (present(contact)) call set_restore(contact%set, act_entry)
  contains
    !> From the stabilised state, Newton without the stabilising force: the equilibrium
    !> exactly, where it is regular (settled), and rep is its report. Where it is not
    !> (frictionless bodies free to slide sideways under no sideways load) q is left as it
    !> was: at the end of the stages the stabilised state stands, its force within
    !> Newton's tolerance.
    subroutine unstabilised(iters, settled)
      integer, intent(inout) :: iters
      logical, intent(out) :: settled
      type(newton_report_t) :: plain
      type(error_t), allocatable :: err_plain
      call newton_solve(model, asm, ls, q, fext, fresh, plain, err_plain, contact=contact, &
                        load_factor=factor)
      iters = iters + plain%iters
      settled = .not. allocated(err_plain) .and. plain%converged
      if (settled) rep = plain
    end subroutine unstabilised
  end subroutine stabilised_solve

  !> The first stage's c [1/s^2]: (E / rho) / L^2 for the stiffest material, so that c M is
  !> about the stiffness of a membrane the scene's size: the first pseudo-step moves a body
  !> about as far as the load would stretch it
  real(dp) function stabilisation(model)
    type(model_t), intent(in) :: model
    integer :: b
    stabilisation = 0
    do b = 1, model%nbody
      stabilisation = max(stabilisation, model%body(b)%young/model%body(b)%density)
    end do
    stabilisation = stabilisation/model%length**2
  end function stabilisation

  !> The largest entry fs of the stabilising force c M (q - q_n) on the free parameters, and
  !> the body it is on
  subroutine stabilising_force(model, asm, q, q_n, c, fs, body)
    type(model_t), intent(in) :: model
    type(assembly_t), intent(in) :: asm
    real(dp), intent(in) :: q(:), q_n(:), c
    real(dp), intent(out) :: fs
    integer, intent(out) :: body
    real(dp), allocatable :: f(:)
    real(dp) :: w(7, 10), v(3, 20)
    integer :: d(7*10), i
    allocate (f(size(q)))
    f = 0
    do i = 1, size(asm%owned)   ! (M on the vector parameters, as the inertia of casca_assembly)
      d = element_dofs(model, asm%owned(i))
      w = reshape(q(d) - q_n(d), [7, 10])
      v(:, 1:10) = w(1:3, :); v(:, 11:20) = w(4:6, :)
      v = c*matmul(v, model%emass(:, :, asm%owned(i)))
      w = 0; w(1:3, :) = v(:, 1:10); w(4:6, :) = v(:, 11:20)
      f(d) = f(d) + reshape(w, [7*10])
    end do
    call sum_all(f)
    f = abs(f)
    where (model%fixed) f = 0
    i = maxloc(f, 1)
    fs = f(i)
    body = model%node_body((i - 1)/ndof_node + 1)
  end subroutine stabilising_force
end module casca_statics
