!> Newton-Raphson on R(q, lambda) = f_int(q) [+ inertia] - f_ext + C^T lambda = 0, g(q) = 0,
!> with the analytic tangent (casca_linear_system solves the saddle-point system).
!>
!> A step is converged only when, for a settled active set, (i) the iterate's error estimated
!> from the last increment and its contraction is within tol of the scene size, and in
!> dynamics within step_share of the step's own motion (down to floor_share of tol), (ii) the
!> residual force at the new iterate, estimated from the last one as the increments contract,
!> is within force_tol of the scene's forces (or below what an error of tol in position
!> makes through the inertia, or in statics below the internal force's round-off:
!> roundoff_floor), and (iii) every active constraint's gap is within the contact
!> tolerance. The active set settles when no multiplier is tensile and no free node
!> penetrates, judged as soon as an iterate is near (settle_incr), not only converged; one
!> that keeps changing is an error (the caller cuts the step), never accepted as it is.
!> max_iter counts the iterations of one active set: a change starts the count again (a hoop's
!> contact nodes going from stick to slip one batch per convergence took 20 iterations in all,
!> and the step was cut although each set converged), and the changes are counted apart, at
!> most max_set_changes (active_set_t%decisions; stick/slip turns alone are not counted,
!> friction_update bounds them). A change is one decision where the set was judged
!> (set_changed), however many constraints it moves: new penetrations taken between them
!> belong to the iterations of the set (counted one each, a plate landing flat and turning,
!> its nodes touching a few at a time and each batch going from stick to slip at once, had
!> its step cut after four decisions).
!>
!> With reuse, a factorisation is kept across iterations and steps while each iteration
!> shrinks the increment fast enough (modified Newton: only the force is assembled then). A
!> step taken with kept factors that does not lower the residual is undone and taken again
!> with fresh factors. A step longer than the one before that overshoots (the derivative of
!> the step's potential along it, dq . R, changes sign and grows) is shortened by a secant
!> line search on that derivative.
module casca_newton
  use casca_kinds, only: dp
  use casca_error, only: error_t, fatal_error
  use casca_strings, only: itoa
  use casca_model, only: model_t, dof
  use casca_assembly, only: assembly_t, assemble
  use casca_follower_loads, only: add_follower_loads   ! pressures and moments
  use casca_linear_system, only: linear_system_t, rows_t, analyse_blocks, factorise_blocks, &
                                 kkt_solve, negative_pivots, follow_bodies
  use casca_contact, only: contact_t, constraint_t, slip, set_restore
  use casca_contact_active_set, only: contact_update, contact_settle, contact_solve_start
  use casca_contact_friction, only: friction_hold
  use casca_contact_rows, only: contact_rows, contact_generalized_force, contact_newton_nrows, &
                                contact_multipliers, contact_set_multipliers, contact_max_gap, &
                                contact_force_points
  use casca_mpi, only: is_root, sum_all
  use casca_timers, only: timer_start, timer_stop, t_assembly, t_contact, t_analysis, t_factor, &
                          t_solve
  implicit none
  private
  public :: newton_opts_t, newton_report_t, newton_solve, contraction

  integer, parameter :: max_hist = 100
  integer, parameter :: max_set_changes = 12   !< active-set decisions per step before a cut
  integer, parameter :: max_backtracks = 4     !< line-search reductions of one increment
  !> an iterate whose last increment is within this share of the scene size decides the active
  !> set (releases, new penetrations; stick and slip wait for convergence): converging each
  !> set to tol before that took a ring thrown at a wall at 100 m/s 1,315 Newton iterations in
  !> 0.6 ms, now 979
  real(dp), parameter :: settle_incr = 1e-3_dp
  !> and in dynamics within this share of the step's motion (settle_tol)
  real(dp), parameter :: settle_share = 0.1_dp
  !> iterations within which Newton converges once the sliding directions follow the slip,
  !> else they are held (slip_rule_changed)
  integer, parameter :: follow_iters = 8
  !> in dynamics the iterate's error is also within this share of the step's motion, but
  !> need not go below floor_share of tol (round-off; a body at rest): step_tol
  real(dp), parameter :: step_share = 1e-4_dp, floor_share = 1e-3_dp
  !> an increment within this factor of tol may be judged by its geometric tail (small_enough)
  real(dp), parameter :: tail_reach = 30

  type :: newton_opts_t
    real(dp) :: tol = 1e-10_dp        !< iterate's error / scene size
    real(dp) :: force_tol = 1e-6_dp   !< residual / scene force
    integer :: max_iter = 25
    logical :: reuse = .true.         !< keep factorisations while they converge fast enough
    logical :: linear = .false.       !< a linear analysis: one increment from the unstressed
                                      !< state, accepted by tolerances that take any (casca_run)
  end type newton_opts_t

  type :: newton_report_t
    integer :: iters = 0              !< passes (each assembles; most solve)
    logical :: converged = .false.
    integer :: nincr = 0              !< increments kept
    real(dp) :: incr(max_hist) = 0    !< max |dq| / scene size of each kept increment
    real(dp) :: energy = 0            !< strain energy at the last assembled iterate
    real(dp) :: residual = 0          !< |R| / scene force: last iterate's (next's if converged)
    real(dp) :: force_scale = 0       !< the scene's force it was judged against [N]
    integer :: neg_pivots = 0         !< of the factors in use (inertia)
    integer :: analyses = 0           !< symbolic analyses done in this solve
    integer :: factorisations = 0     !< numerical factorisations done in this solve
    integer :: factored_at = 0        !< the iteration of the last of them (0: none)
    integer :: refreshes = 0          !< steps of kept factors undone and taken afresh
    integer :: backtracks = 0         !< line-search reductions
  end type newton_report_t

  !> The last increment, to undo or shorten it
  type :: increment_t
    real(dp), allocatable :: q(:), dq(:), lambda(:), dlambda(:)
    real(dp) :: g0 = 0, r0 = 0        !< dq . R and |R| where it was taken
    real(dp) :: alpha = 1, g = 0      !< the fraction taken, and dq . R there
    logical :: stale = .false.        !< taken with kept factors
    !> taken mostly to close constraints' gaps (a contact just added, a stick's slip): the
    !> force residual must rise then (the contact force appears), so it does not judge it
    logical :: closing = .false.
    integer :: set = -1               !< active-set version it was taken with (-1: judged)
    integer :: cuts = 0
  end type increment_t

contains

  !> On failure (err allocated) q and the contact's active set are as they were at entry.
  subroutine newton_solve(model, asm, ls, q, fext, opts, rep, err, cm, qs, contact, qn, af, load_factor)
    type(model_t), intent(in) :: model
    type(assembly_t), intent(inout) :: asm
    type(linear_system_t), intent(inout) :: ls
    real(dp), intent(inout) :: q(:)
    real(dp), intent(in) :: fext(:)
    type(newton_opts_t), intent(in) :: opts
    type(newton_report_t), intent(out) :: rep
    type(error_t), allocatable, intent(out) :: err
    real(dp), intent(in), optional :: cm, qs(:)
    type(contact_t), intent(inout), optional :: contact
    real(dp), intent(in), optional :: qn(:), af   !< generalized-alpha: f_int at (1-af) q + af qn
    real(dp), intent(in), optional :: load_factor   !< of the pressures (statics; default 1)
    real(dp), allocatable :: r(:), res(:), q_entry(:)
    type(constraint_t), allocatable :: act_entry(:)
    type(rows_t) :: rows
    type(increment_t) :: inc
    integer :: it, it_set, nc, version
    integer :: set_start   !< the first increment of the current active set
    integer :: follow_start   !< the iteration after which the sliding directions followed the slip
    real(dp) :: fref, ffloor, rnorm, fpress   ! fpress: the pressures' and moments' force scale
    real(dp) :: taken(max_hist)   !< rep%incr before any line-search shortening
    logical :: fresh, refresh_next

    rep%converged = asm%neq_total == 0   ! every body is frozen this step: nothing to solve
    if (rep%converged) return
    allocate (r(model%ndof), res(model%ndof))
    q_entry = q
    if (present(contact)) then
      call contact_solve_start(contact)
      act_entry = contact%set%act(1:contact%set%nact)
    end if
    ffloor = 0
    if (present(cm)) ffloor = inertial_floor(model, cm, opts%tol)
    if (.not. present(qn)) ffloor = max(ffloor, roundoff_floor(model))   ! (statics)
    refresh_next = .false.
    it_set = 0; set_start = 1
    do it = 1, max_hist
      it_set = it_set + 1
      if (it_set > opts%max_iter) exit
      rep%iters = it
      call constraints(reproject=it == 1)
      call timer_start(t_analysis)
      call analyse_blocks(ls, model, asm, rows, rep%analyses, err)
      call timer_stop(t_analysis)
      if (allocated(err)) exit
      fresh = refresh_needed(ls, opts, rep, it, set_start, nc, refresh_next)
      call timer_start(t_assembly)
      call assemble(model, asm, q, fresh, r, rep%energy, cm, qs, qn, af)
      r = r - fext
      call add_follower_loads(model, asm, q, fresh, r, fpress, load_factor, qn, af)
      call timer_stop(t_assembly)
      call full_residual()
      if (it > 1) then   ! (judged before factorising: an iterate left is not factorised)
        if (undo_or_shorten()) then
          refresh_next = refresh_next .or. fresh
          cycle
        end if
      end if
      if (fresh) then
        call timer_start(t_factor)
        call factorise_blocks(ls, model, asm, rows, q, err)
        call timer_stop(t_factor)
        if (allocated(err)) exit
        rep%factorisations = rep%factorisations + 1; rep%factored_at = it
      end if
      call take_increment()
      if (allocated(err)) exit
      if (refresh_next) cycle   ! (the increment was undone)
      ! (a new rule for the sliding directions: the residual's change is not the increment's)
      if (slip_rule_changed(it, settling(rep, set_start, settle_tol(q, model%length, qn)), follow_start, contact)) inc%set = -1
      if (.not. small_enough(rep, step_tol(opts%tol, q, model%length, qn))) then
        if (near_enough(rep, set_start, settle_tol(q, model%length, qn), contact)) then
          if (set_changed(stick=.false.)) call new_set()
          if (allocated(err)) exit
        end if
        cycle
      end if
      if (residual_estimate() > max(opts%force_tol*fref, ffloor)) cycle
      if (slip_held(it, follow_start, contact)) then
        inc%set = -1; cycle
      end if
      if (set_changed(stick=.true.)) then
        if (allocated(err)) exit
        call new_set()
        cycle
      end if
      if (gap_open()) cycle
      rep%converged = .true.
      rep%residual = residual_estimate()/max(fref, tiny(1._dp))
      rep%neg_pivots = negative_pivots(ls, asm, nc)
      return
    end do
    if (.not. allocated(err)) call fatal_error(err, failure_message(rep, rnorm, fref, &
      rep%nincr > 0 .and. small_enough(rep, step_tol(opts%tol, q, model%length, qn)) .and. &
      rnorm <= max(opts%force_tol*fref, ffloor)))
    q = q_entry
    if (present(contact)) call set_restore(contact%set, act_entry)
  contains

    !> the active constraints at q (with reproject, their points projected again; new
    !> penetrations added while the set may still change) and their rows
    subroutine constraints(reproject)
      logical, intent(in) :: reproject
      integer :: added
      nc = 0
      version = 0
      call timer_start(t_contact)
      if (present(contact)) then
        call contact_update(contact, model, q, contact%set%decisions < max_set_changes, added, &
                            reproject=reproject)
        nc = contact_newton_nrows(contact)
        if (present(qn) .and. present(af)) call contact_force_points(contact, model, af, q, qn)
        call contact_rows(contact, model, asm%eq, asm%neq, rows%irn, rows%jcn, rows%val, rows%gap, &
                          rows%key, rows%fval)
        version = contact%set%changes
      else if (.not. allocated(rows%gap)) then
        allocate (rows%irn(0), rows%jcn(0), rows%val(0), rows%gap(0), rows%key(2, 0), rows%fval(0))
      end if
      call timer_stop(t_contact)
    end subroutine constraints

    !> res = r + C^T lambda on the free parameters, its largest entry rnorm, and the scale of
    !> the scene's forces: the loads, the internal and inertial force, the multipliers' force
    subroutine full_residual()
      res = r
      if (nc > 0) then   ! + C^T lambda: on the fibres and thicknesses too, with faces
        call contact_generalized_force(contact, model, res)
        res = r + res
      end if
      where (model%fixed) res = 0
      rnorm = maxval(abs(res))
      fref = max(maxval(abs(fext)), fpress, maxval(abs(r + fext), mask=.not. model%fixed), &
                 maxval(abs(res - r), mask=.not. model%fixed))
      rep%residual = rnorm/max(fref, tiny(1._dp)); rep%force_scale = fref   ! (also on failure)
    end subroutine full_residual

    !> the residual at the new iterate: the last one, shrunk as the increments contract
    real(dp) function residual_estimate()
      residual_estimate = rnorm
      if (rep%nincr >= 2) residual_estimate = rnorm*min(1._dp, contraction(rep))
    end function residual_estimate

    !> Judge the last increment by the residual it led to (same active set only): undo a
    !> step of kept factors that did not lower the residual (fresh factors next), shorten a
    !> step that overshot. True when q was moved back.
    logical function undo_or_shorten()
      real(dp) :: s, alpha
      undo_or_shorten = .false.
      if (inc%set /= version .or. inc%g0 >= 0 .or. inc%closing) return
      inc%g = dot_product(inc%dq, res)
      if (inc%stale .and. .not. (rnorm <= inc%r0)) then   ! (also NaN)
        call undo()
        undo_or_shorten = .true.
        return
      end if
      ! only a step longer than the one before (of the same set, as it was taken: one cut
      ! to a tenth leaves nine tenths to go) is judged: Newton's own path may raise the
      ! residual on the way (a strip bending through large rotations does), but a growing
      ! increment is divergence in the making
      if (rep%nincr < set_start + 1 .or. inc%cuts >= max_backtracks) return
      if (inc%cuts == 0 .and. rep%incr(rep%nincr) <= taken(rep%nincr - 1)) return
      s = inc%g/inc%g0   ! < 0: past the minimum along the step
      if (s >= -0.8_dp*inc%alpha) return
      ! secant between the start (alpha 0, g0) and the point taken (alpha, g)
      alpha = max(0.1_dp*inc%alpha, inc%alpha*inc%g0/(inc%g0 - inc%g))
      call move_to(alpha)
      rep%incr(rep%nincr) = rep%incr(rep%nincr)*alpha/inc%alpha
      inc%alpha = alpha
      inc%cuts = inc%cuts + 1
      rep%backtracks = rep%backtracks + 1
      undo_or_shorten = .true.
    end function undo_or_shorten

    !> back to where the last increment started; fresh factors next
    subroutine undo()
      call move_to(0._dp)
      rep%nincr = rep%nincr - 1
      rep%refreshes = rep%refreshes + 1
      refresh_next = .true.
      inc%set = -1
    end subroutine undo

    subroutine move_to(alpha)
      real(dp), intent(in) :: alpha
      q = inc%q + alpha*inc%dq
      if (size(inc%lambda) > 0) call contact_set_multipliers(contact, inc%lambda + alpha*inc%dlambda)
    end subroutine move_to

    !> solve the saddle-point system for (dq, dlambda) and step
    subroutine take_increment()
      real(dp), allocatable :: d(:)
      logical :: renew
      renew = .false.
      if (rep%nincr >= set_start + 1) renew = contraction(rep) > 0.25_dp
      call solve_increment(model, asm, ls, rows, q, res, renew, d, err)
      if (allocated(err)) return
      inc%q = q; inc%dq = d(1:model%ndof); inc%dlambda = d(model%ndof + 1:)
      if (nc > 0) then
        inc%lambda = contact_multipliers(contact)
      else
        inc%lambda = [real(dp) ::]
      end if
      inc%g0 = dot_product(inc%dq, res); inc%r0 = rnorm
      inc%alpha = 1; inc%cuts = 0; inc%stale = .not. fresh; inc%set = version
      inc%closing = .false.   ! (the gaps a tenth of the step or more)
      if (nc > 0) inc%closing = maxval(abs(rows%gap)) > max(contact%opt%tol, 0.1_dp*maxval(abs(inc%dq)))
      call move_to(1._dp)
      rep%nincr = rep%nincr + 1
      rep%incr(rep%nincr) = maxval(abs(inc%dq))/model%length
      taken(rep%nincr) = rep%incr(rep%nincr)
      if (.not. (rep%incr(rep%nincr) <= 1e6_dp)) then   ! also catches NaN
        if (inc%stale) then   ! kept factors: undo, and try fresh ones
          call undo()
        else
          call fatal_error(err, 'Newton iteration diverged')
        end if
      end if
    end subroutine take_increment

    !> each set has its own max_iter (at most max_set_changes sets)
    subroutine new_set()
      it_set = 0
      set_start = rep%nincr + 1
      if (present(contact)) contact%follow_slip = .false.
    end subroutine new_set

    !> converged for this set: stick/slip, releases and new penetrations (contact_settle;
    !> stick = .false.: near, not converged, stick and slip left for later). True when the
    !> set changed; an error when it keeps changing.
    logical function set_changed(stick)
      logical, intent(in) :: stick
      integer :: changed
      set_changed = .false.
      if (.not. present(contact)) return
      call timer_start(t_contact)
      call contact_settle(contact, model, q, stick, changed)
      call timer_stop(t_contact)
      set_changed = changed > 0
      if (set_changed .and. contact%set%decisions >= max_set_changes) &
        call fatal_error(err, 'the contact active set did not settle')
    end function set_changed

    !> an active constraint whose gap at the new iterate is beyond the contact tolerance
    logical function gap_open()
      gap_open = .false.
      if (.not. present(contact)) return
      gap_open = contact_max_gap(contact) > contact%opt%tol
    end function gap_open

  end subroutine newton_solve

  !> Sliding directions follow the slip (friction_geometry) from the first iterate of a set
  !> that is near, as settle_incr decides the active set: from the far ones (a step's
  !> predictor, a new contact) they swung by a radian from iterate to iterate, and Newton
  !> cycled (a ball sliding inside a shell). follow_iters iterations after that without
  !> convergence, they are held at the solve's start for the rest of it (friction_hold).
  !> True when the rule changed at this iterate it.
  logical function slip_rule_changed(it, near, follow_start, contact) result(changed)
    integer, intent(in) :: it
    logical, intent(in) :: near
    integer, intent(inout) :: follow_start   !< the iterate after which they followed
    type(contact_t), intent(inout), optional :: contact
    changed = .false.
    if (.not. present(contact)) return
    if (contact%hold_slip) return
    if (contact%follow_slip) then
      if (it - follow_start >= follow_iters) then
        call friction_hold(contact); changed = .true.
      end if
    else if (near) then
      contact%follow_slip = .true.; follow_start = it; changed = .true.
    end if
  end function slip_rule_changed

  !> Converged with the sliding directions held (a set that converged before it was near):
  !> they follow the slip from here, and Newton goes on
  logical function slip_held(it, follow_start, contact)
    integer, intent(in) :: it
    integer, intent(inout) :: follow_start
    type(contact_t), intent(inout), optional :: contact
    slip_held = .false.
    if (.not. present(contact)) return
    if (contact%follow_slip .or. contact%hold_slip) return
    if (.not. any(contact%set%act(1:contact%set%nact)%grip == slip)) return
    contact%follow_slip = .true.; follow_start = it
    slip_held = .true.
  end function slip_held

  !> A new matrix unless the kept one still contracts the increment fast enough (decided
  !> from replicated figures, so alike on every rank). With constraints, slow contraction
  !> comes first from the rows (their normal is held): Z is renewed first, K only if
  !> contraction stays poor. Increments of two active sets say nothing of the factors.
  !> A step's first iteration uses kept factors as ls's probes allow, and its second and
  !> third judge them, while the active set is the step's first. After 9 iterations of one
  !> set the factors are always fresh; counted over the step, the iterations of earlier sets
  !> made every later one factorise (a pressurised ball at a rough wall, three sets a step:
  !> 94 factorisations in 2.1 ms, now 44, and 0.69 of the wall).
  logical function refresh_needed(ls, opts, rep, it, set_start, nc, refresh_next) result(fresh)
    type(linear_system_t), intent(inout) :: ls
    type(newton_opts_t), intent(in) :: opts
    type(newton_report_t), intent(in) :: rep
    integer, intent(in) :: it, set_start, nc
    logical, intent(inout) :: refresh_next
    fresh = refresh_next .or. .not. (opts%reuse .and. ls%solver(1)%factored)
    refresh_next = .false.
    if (it == 1) then
      call ls%judge_probe(.false.)   ! (a probe still open passed: its step converged on them)
      if (.not. fresh) fresh = .not. ls%start_with_kept()
    end if
    if (.not. fresh .and. rep%nincr >= set_start + 1) then
      if (ls%schur .and. nc > 0) then
        if (rep%nincr >= 3) fresh = contraction(rep) > 0.5_dp
      else
        fresh = contraction(rep) > 0.25_dp
      end if
      if (rep%nincr - set_start >= 8) fresh = .true.
    end if
    if (it >= 2 .and. set_start == 1 .and. (fresh .or. it >= 3)) call ls%judge_probe(fresh)
  end function refresh_needed

  !> The last increment over the one before
  real(dp) pure function contraction(rep)
    type(newton_report_t), intent(in) :: rep
    contraction = rep%incr(rep%nincr)/max(rep%incr(rep%nincr - 1), tiny(1._dp))
  end function contraction

  !> The iterate's error allowed: tol of the scene size, and in dynamics (qn, the step's
  !> start) step_share of the step's motion so far. Each step's error is left in the next
  !> step's start, and with kept factors (contracting, not quadratic) it is about tol every
  !> step, of one sign while the motion is smooth: summed over the steps it grows as 1/dt (a
  !> soft cantilever under a tip load at 3,200 steps of 156 us ended 2.4% of its deflection
  !> low, at 4 times the step 0.05%; and tolerance = 1e-8 gave a larger error than 1e-4).
  !> Held to a share of the motion the error over a run stays that share of the path
  !> travelled.
  pure real(dp) function step_tol(tol, q, length, qn)
    real(dp), intent(in) :: tol, q(:), length
    real(dp), intent(in), optional :: qn(:)
    step_tol = tol
    if (present(qn)) step_tol = max(min(tol, step_share*maxval(abs(q - qn))/length), floor_share*tol)
  end function step_tol

  !> The iterate's error, not the last increment, within tol: with contraction rho < 1/2
  !> what is left after this increment is at most about incr rho / (1 - rho) (a geometric
  !> tail), which saves the last iteration whose only use would be to measure it. Trusted
  !> within tail_reach of tol only: rho from the first two increments is the predictor's
  !> error over Newton's, no measure of the kept factors' contraction, and an error left
  !> in q is 2/dt of it in the velocity (the midpoint rule), of one sign from step to step
  !> (a free hoop spinning under tolerance = 1e-5, its second increments up to 130 tol:
  !> angular momentum lost 5e-4, now 1.3e-9; the thesis' two rings take 1.7% more iterations)
  logical pure function small_enough(rep, tol)
    type(newton_report_t), intent(in) :: rep
    real(dp), intent(in) :: tol
    real(dp) :: rho, nrm
    nrm = rep%incr(rep%nincr)
    small_enough = nrm <= tol
    if (small_enough .or. rep%nincr < 2 .or. nrm > tail_reach*tol) return
    rho = contraction(rep)
    if (rho < 0.5_dp) small_enough = nrm*rho/(1 - rho) <= tol
  end function small_enough

  !> Close enough to decide the active set: the increments of the set (from its first,
  !> set_start) contract, the last within settle_incr. A set that will change need not
  !> converge to tol first. Only the first half of the changes a step may make are made so;
  !> the rest wait for convergence, where the multipliers' signs are sure (three tubes in a
  !> pile: 18 and 6 constraints in turn, released and taken again from near iterates, until
  !> the step was cut)
  logical pure function near_enough(rep, set_start, near, contact)
    type(newton_report_t), intent(in) :: rep
    integer, intent(in) :: set_start
    real(dp), intent(in) :: near   !< settle_tol
    type(contact_t), intent(in), optional :: contact
    near_enough = .false.
    if (.not. present(contact)) return
    if (contact%set%decisions >= max_set_changes/2) return
    near_enough = settling(rep, set_start, near)
  end function near_enough

  !> The increments of the set (from its first, set_start) contract, the last within near
  !> (settle_tol)
  logical pure function settling(rep, set_start, near)
    type(newton_report_t), intent(in) :: rep
    integer, intent(in) :: set_start
    real(dp), intent(in) :: near
    settling = .false.
    if (rep%nincr >= set_start + 1) settling = rep%incr(rep%nincr) <= near .and. contraction(rep) < 1
  end function settling

  !> How near an iterate decides the active set: settle_incr of the scene size, and in
  !> dynamics (qn, the step's start) within settle_share of the step's motion so far. An
  !> increment larger than the step's motion leaves the multipliers' signs to chance: thin
  !> plates landing in a stack, in steps of 62.5 us moving them 12 um, were judged at 0.2 mm
  !> (1e-3 of the scene), released tens of sliding nodes that came straight back deeper, and
  !> ran out of decisions
  pure real(dp) function settle_tol(q, length, qn)
    real(dp), intent(in) :: q(:), length
    real(dp), intent(in), optional :: qn(:)
    settle_tol = settle_incr
    if (present(qn)) settle_tol = min(settle_incr, settle_share*maxval(abs(q - qn))/length)
  end function settle_tol

  !> The round-off of the internal force, below which no residual can be asked for: the shell's
  !> strains come from positions, so a position known to eps |x| (|x| its coordinates' size,
  !> not the element's) is a strain error eps |x| / l_e and a nodal force error of the
  !> membrane stiffness E h / (1 - nu^2) times eps |x|, whatever the load. Measured: the
  !> unloaded f_int of plates, a sphere and a ring 0.1 to 1.5 times eps E h max|x| (plates of
  !> 2 to 16 cells, moved 1e2 to 1e6 from the origin: it grows with |x|, not with l_e); a
  !> simply supported plate's residual at 10 and 0.1 Pa stalls at 2 to 6 times it (it was asked
  !> for 1e-6 of the load's forces, 20 iterations a load step, then halvings; at 1e-4 Pa the
  !> stabilised path). 32 times: above that, at most a few per cent of force_tol at loads of
  !> sound size (1000 Pa on it). Statics only: in dynamics the inertia's floor and forces rule.
  real(dp) function roundoff_floor(model)
    type(model_t), intent(in) :: model
    real(dp), parameter :: factor = 32
    integer :: b
    roundoff_floor = 0
    do b = 1, model%nbody
      associate (bd => model%body(b))
        roundoff_floor = max(roundoff_floor, bd%young*bd%thickness/(1 - bd%poisson**2)* &
                             maxval(abs(model%x0(:, bd%node_first:bd%node_last))))
      end associate
    end do
    roundoff_floor = factor*epsilon(1._dp)*roundoff_floor
  end function roundoff_floor

  !> Force of the inertia of the heaviest element moved by tol of the scene size in one step
  !> (cm: the inertia's factor): below it the residual is round-off of the inertial terms
  real(dp) function inertial_floor(model, cm, tol)
    type(model_t), intent(in) :: model
    real(dp), intent(in) :: cm, tol
    integer :: e
    inertial_floor = 0
    do e = 1, model%nelem
      inertial_floor = max(inertial_floor, sum(model%emass(1:10, 1:10, e)))
    end do
    inertial_floor = cm*inertial_floor*tol*model%length
  end function inertial_floor

  !> Solve the saddle-point system for the increment d = (dq, dlambda) of the residual res
  !> and the rows' gaps, gathered whole on every rank
  subroutine solve_increment(model, asm, ls, rows, q, res, renew, d, err)
    type(model_t), intent(in) :: model
    type(assembly_t), intent(in) :: asm
    type(linear_system_t), intent(inout) :: ls
    type(rows_t), intent(in) :: rows
    real(dp), intent(in) :: q(:)   !< the iterate (the bodies' turn since K's factors)
    real(dp), intent(in) :: res(:)
    logical, intent(in) :: renew
    real(dp), allocatable, intent(out) :: d(:)
    type(error_t), allocatable, intent(out) :: err
    real(dp), allocatable :: b(:), x(:)
    integer :: i, nc
    nc = size(rows%gap)
    allocate (b(asm%neq + nc), x(asm%neq + nc), d(model%ndof + nc))
    do i = 1, model%ndof
      if (asm%eq(i) > 0) b(asm%eq(i)) = -res(i)
    end do
    b(asm%neq + 1:) = -rows%gap
    call timer_start(t_solve)
    call follow_bodies(ls, model, q)   ! (no turn right after a factorisation at q)
    call kkt_solve(ls, asm, rows, b, renew, x, err)
    if (allocated(err)) then
      call timer_stop(t_solve); return
    end if
    ! each block's host gives its part (x is zero in the blocks a rank does not host), rank 0
    ! the multipliers' (every rank has them with 'schur'; rank 0 is the only host with 'saddle')
    d = 0
    do i = 1, model%ndof
      if (asm%eq(i) > 0) d(i) = x(asm%eq(i))
    end do
    if (is_root()) d(model%ndof + 1:) = x(asm%neq + 1:)
    call sum_all(d)
    call timer_stop(t_solve)
  end subroutine solve_increment

  function failure_message(rep, rnorm, fref, within) result(msg)
    type(newton_report_t), intent(in) :: rep
    real(dp), intent(in) :: rnorm, fref
    logical, intent(in) :: within   !< the last iterate was within Newton's tolerances
    character(len=:), allocatable :: msg
    character(len=160) :: buf
    write (buf, '(a,i0,a,es9.2,a,es9.2,a)') 'Newton did not converge in ', rep%iters, &
      ' iterations (last increment ', rep%incr(max(rep%nincr, 1)), &
      ' of the scene size, residual ', rnorm/max(fref, tiny(1._dp)), ' of the scene force)'
    msg = trim(buf)
    ! (both figures below the tolerances read as a contradiction to a validator)
    if (within) msg = msg//': its iterates were within the tolerances, but the contacts kept '// &
                      'changing (constraints taken or let go, or nodes turning between stick and slip)'
    ! (newton_max_iter is each active set's; a reader of 100 looked for a 100 in the deck)
    if (rep%iters >= max_hist) msg = msg//'; '//itoa(max_hist)//' is the most a step takes '// &
                                     'over all its active sets'
  end function failure_message
end module casca_newton
