!> The commands that work on a deck: `check` (read, sanity, build) and `run` (the time loop:
!> step, account, write). Exit codes: 0 done, 2 bad input, 3 the solver could not go on.
module casca_run
  use casca_kinds, only: dp
  use casca_error, only: error_t
  use casca_deck, only: deck_t, read_deck, unset, add_problem
  use casca_sanity, only: check_deck
  use casca_scene, only: build_model, initial_state, tracked_nodes, scene_contact
  use casca_model, only: model_t, reference_state, dof
  use casca_assembly, only: assembly_t, assembly_setup
  use casca_linear_system, only: linear_system_t
  use casca_mass_solver, only: mass_setup
  use casca_newton, only: newton_opts_t, newton_report_t
  use casca_newmark, only: state_t, newmark_t, newmark_step, static_solve
  use casca_accounting, only: balance_t, energy_term_t, account, gravity_load, balance_summary, &
                              energy_balance
  use casca_output, only: output_t, output_open, output_history, output_frame, output_close, &
                          output_flush, output_release
  use casca_vtu_writer, only: field_t, field
  use casca_contact, only: contact_t
  use casca_contact_active_set, only: contact_update
  use casca_contact_rows, only: contact_force_total, contact_nodal_fields
  use casca_contact_probes, only: contact_penetration, contact_signed_distance
  use casca_pair_report, only: pair_normal_force, pair_active_count, pair_labels
  use casca_contact_friction, only: pair_tangential_force
  use casca_checkpoint, only: save_checkpoint, load_checkpoint
  use casca_plots, only: make_plots
  use casca_pair_gaps, only: pair_gap_t, pair_gaps, pair_gap_lines
  use casca_files, only: folder_of
  use casca_free_flight, only: idle_bodies, clear_near_contact, advance_idle
  use casca_mpi, only: is_root, wall_time, n_ranks, share_error
  use casca_timers, only: timer_start, timer_stop, timer_report, seconds, t_account, t_output
  implicit none
  private
  public :: load_scene, run_deck

  integer, parameter, public :: exit_ok = 0, exit_input = 2, exit_solver = 3

contains

  !> Read, check and build; print every problem on rank 0. code = exit_input on problems.
  !> gaps: also print each contact pair's initial gap and time to contact (casca check).
  subroutine load_scene(path, deck, model, code, gaps)
    character(len=*), intent(in) :: path
    type(deck_t), intent(out) :: deck
    type(model_t), intent(out) :: model
    integer, intent(out) :: code
    logical, intent(in), optional :: gaps
    integer :: i
    call read_deck(path, deck)
    if (deck%nproblems == 0) call check_deck(deck)
    if (deck%nproblems == 0) call build_model(deck, model)
    if (deck%nproblems == 0) call check_overlap()
    if (present(gaps)) then
      if (gaps .and. deck%nproblems == 0) call gap_report()
    end if
    code = exit_ok
    if (deck%nproblems > 0) then
      if (is_root()) then
        do i = 1, deck%nproblems
          write (0, '(a,a)') 'error: ', trim(deck%problems(i))
        end do
        write (0, '(i0,a)') deck%nproblems, ' problem(s) in the deck; nothing was run'
      end if
      code = exit_input
    end if
  contains
    !> bodies of a contact pair that overlap at the start are refused, never ignored
    subroutine check_overlap()
      type(contact_t) :: probe
      real(dp), allocatable :: q(:)
      integer :: added, k, worst
      logical :: found
      character(len=512) :: msg
      call scene_contact(deck, model, probe, found)
      if (.not. found) return
      allocate (q(model%ndof))
      call reference_state(model, q)
      call contact_update(probe, model, q, .true., added)
      if (added == 0) return
      worst = minloc(probe%act(1:probe%nact)%gap, dim=1)
      k = probe%act(worst)%node
      write (msg, '(a,a,a,a,a,i0,a,es10.3,a,i0,a)') 'bodies ''', &
        trim(model%body(model%node_body(k))%name), ''' and ''', &
        trim(target_name(probe%pair(2, probe%act(worst)%pair))), ''' overlap at the start: node ', &
        k - model%body(model%node_body(k))%node_first + 1, ' is ', -probe%act(worst)%gap, &
        ' m inside (', added, ' nodes in all); move them apart'
      if (probe%faces) msg = trim(msg)//' (contact is between the shell faces: half of each '// &
                             'thickness from the mid-surface)'
      call add_problem(deck, 0, trim(msg))
    end subroutine check_overlap

    !> each pair's gap and time to contact at t = 0 (pair_gaps.f90), on rank 0
    subroutine gap_report()
      type(contact_t) :: probe
      type(state_t) :: st0
      type(pair_gap_t), allocatable :: pg(:)
      character(len=320), allocatable :: lines(:)
      character(len=64), allocatable :: bnames(:), onames(:)
      integer :: k, n
      logical :: found
      if (.not. is_root()) return
      call scene_contact(deck, model, probe, found)
      if (.not. found) return
      call initial_state(deck, model, st0)
      pg = pair_gaps(probe, model, reshape(st0%q([((dof(n, k), k=1, 3), n=1, model%nnode)]), &
                     [3, model%nnode]), reshape(st0%q([((dof(n, k), k=4, 6), n=1, model%nnode)]), &
                     [3, model%nnode]), reshape(st0%qd([((dof(n, k), k=1, 3), n=1, model%nnode)]), &
                     [3, model%nnode]))
      allocate (bnames(model%nbody), onames(size(probe%obstacle)))
      do k = 1, model%nbody
        bnames(k) = model%body(k)%name
      end do
      do k = 1, size(onames)
        onames(k) = probe%obstacle(k)%name
      end do
      lines = pair_gap_lines(probe, pg, bnames, onames)
      do k = 1, size(lines)
        print '(a)', trim(lines(k))
      end do
    end subroutine gap_report

    !> a body's name, or an obstacle's (target -k)
    function target_name(t) result(name)
      integer, intent(in) :: t
      character(len=:), allocatable :: name
      if (t > 0) then
        name = model%body(t)%name
      else
        name = deck%obstacles(-t)%name
      end if
    end function target_name
  end subroutine load_scene

  subroutine run_deck(path, out_dir, restart, quiet, code)
    character(len=*), intent(in) :: path, out_dir, restart
    logical, intent(in) :: quiet
    integer, intent(out) :: code
    type(deck_t) :: deck
    type(model_t) :: model
    type(assembly_t) :: asm
    type(linear_system_t), allocatable :: ls   ! (large: MUMPS structures)
    type(newton_opts_t) :: opts
    type(newton_report_t) :: rep
    type(state_t) :: st
    type(newmark_t) :: nm
    type(balance_t) :: bal, bal0   !< now, and at the start of the run
    type(output_t) :: out
    type(contact_t), allocatable :: contact   !< not allocated: no contact (absent below)
    type(error_t), allocatable :: err
    real(dp), allocatable :: fext(:), fgrav(:), q0(:), q_before(:), qd_before(:)
    logical, allocatable :: frozen(:), idle(:)
    integer, allocatable :: tracked(:)
    character(len=128), allocatable :: labels(:)
    character(len=:), allocatable :: dir
    real(dp) :: interval, next_frame, next_ckpt, t0, dt
    integer :: level, k, restart_step, total_newton
    logical :: missing, use_contact
    real(dp) :: pen, gmax
    type :: progress_t   !< where the last progress line was
      real(dp) :: wall = 0, t = 0
      integer :: step = 0, newton = 0
    end type progress_t
    type(progress_t) :: last

    code = exit_ok
    call load_scene(path, deck, model, code)
    if (code /= exit_ok) return
    allocate (ls)
    dir = trim(deck%output%dir)
    if (out_dir /= '') dir = trim(out_dir)

    call setup_contact()
    if (failed('setup')) return
    call assembly_setup(model, asm, err, split=split_bodies())
    if (failed('setup')) return
    if (deck%run%ordering == 'metis') ls%solver%ordering = 1
    opts%tol = deck%run%newton_tol; opts%max_iter = deck%run%newton_max_iter
    opts%reuse = deck%run%reuse_factorisation
    allocate (fgrav(model%ndof))
    call gravity_load(model, fgrav)
    fext = model%fext + fgrav
    call tracked_nodes(deck, model, tracked)
    allocate (labels(size(tracked)))
    do k = 1, size(tracked)
      write (labels(k), '(a,a,i0,a,3(g0.4,:,", "))') trim(model%body(model%node_body(tracked(k)))%name), &
        ' node ', tracked(k) - model%body(model%node_body(tracked(k)))%node_first + 1, &
        ' near (', deck%output%track(:, k)
      labels(k) = trim(labels(k))//')'
    end do
    call initial_state(deck, model, st)
    allocate (q0(model%ndof))
    call reference_state(model, q0)

    level = 0; restart_step = -1
    if (restart /= '') then   ! (statics: t is the load factor, <= 1)
      call load_checkpoint(restart, model, merge(1._dp, deck%run%t_end, deck%run%analysis == &
                           'static'), deck%run%max_step_cuts, st, level, err, contact)
      if (failed('restart')) return
      restart_step = st%step
    end if
    call open_history()
    if (failed('output')) return

    t0 = wall_time()
    if (deck%run%analysis == 'static') then
      call static_run()
      return
    end if

    nm%beta = deck%run%beta; nm%gamma = deck%run%gamma
    dt = deck%run%dt
    interval = deck%output%interval
    if (interval == unset) interval = deck%run%t_end/100
    interval = max(interval, dt)
    next_frame = (floor(st%t/interval + 1e-9_dp) + 1)*interval
    next_ckpt = huge(1._dp)
    if (deck%output%checkpoint_interval > 0) &
      next_ckpt = (floor(st%t/deck%output%checkpoint_interval + 1e-9_dp) + 1)*deck%output%checkpoint_interval
    if (restart_step < 0) then
      call start_acceleration()
      call account(model, asm, st, fext, q0, bal)
      bal0 = bal
      call history_row(0)
      if (failed('history')) return
      call frame()
      if (failed('frame')) return
    end if
    if (is_root() .and. .not. quiet) print '(a,i0,a,i0,a,i0,a,i0,a)', 'casca: ', model%nbody, &
      ' bodies, ', model%nelem, ' elements, ', asm%neq_total, ' unknowns, ', n_ranks, ' rank(s)'
    if (is_root() .and. .not. quiet .and. n_ranks > 1) print '(a,*(a,:,"; "))', &
      'casca: bodies solved on ', (trim(model%body(k)%name)//': '//ranks_of(k), k=1, model%nbody)

    total_newton = 0
    last = progress_t(t0, st%t, st%step, 0)
    allocate (frozen(model%ndof), idle(model%nbody))
    frozen = .false.; idle = .false.
    do while (st%t < deck%run%t_end - 1e-9_dp*dt)
      nm%dt = min(dt/2**level, deck%run%t_end - st%t)
      if (deck%run%skip_idle_bodies) call update_frozen()
      if (allocated(err)) then
        call give_up(err%message); return
      end if
      q_before = st%q; qd_before = st%qd
      call newmark_step(model, asm, ls, nm, fext, opts, st, rep, err, contact)
      if (allocated(err)) then
        if (level < deck%run%max_step_cuts) then
          level = level + 1   ! the state is unchanged: retry with half the step
          if (is_root() .and. .not. quiet) print '(a,es10.3,a,a)', 'step cut to dt = ', &
            dt/2**level, ': ', err%message
          deallocate (err)
          cycle
        end if
        call give_up(err%message)
        return
      end if
      total_newton = total_newton + rep%iters
      if (any(idle)) call advance_idle(model, idle, nm%dt, q_before, qd_before, st%q, st%qd, st%qdd)
      if (level > 0 .and. rep%iters <= 3) level = level - 1   ! Newton is at ease: grow back
      call timer_start(t_account)
      call account(model, asm, st, fext, q0, bal)
      call timer_stop(t_account)
      call timer_start(t_output)
      call history_row(rep%iters)
      call timer_stop(t_output)
      if (failed('history')) return
      if (st%t >= next_frame - 1e-9_dp*dt .or. st%t >= deck%run%t_end - 1e-9_dp*dt) then
        call timer_start(t_output)
        call frame()
        call timer_stop(t_output)
        if (failed('frame')) return
        next_frame = next_frame + interval
        if (is_root() .and. .not. quiet) call progress()
      end if
      if (st%t >= next_ckpt - 1e-9_dp*dt) then
        call checkpoint()
        if (code /= exit_ok) return
        next_ckpt = next_ckpt + deck%output%checkpoint_interval
      end if
    end do
    call checkpoint()
    if (code /= exit_ok) return
    call finish()

  contains

    !> Leave the bodies that need no solving this step out of the equations (re-analysed
    !> only when that set changes).
    subroutine update_frozen()
      logical, allocatable :: fz(:)
      integer :: b
      if (use_contact) contact%time = st%t
      call idle_bodies(model, st%q, st%qd, st%qdd, fext, nm%dt, idle, contact)
      allocate (fz(model%ndof))
      fz = .false.
      do b = 1, model%nbody
        if (idle(b)) fz(dof(model%body(b)%node_first, 1):dof(model%body(b)%node_last, 7)) = .true.
      end do
      if (all(fz .eqv. frozen)) return
      frozen = fz
      call assembly_setup(model, asm, err, frozen, split_bodies())
      call ls%new_pattern()
    end subroutine update_frozen

    !> The ranks that factorise and solve body b's block (when every body is solved)
    function ranks_of(b) result(str)
      integer, intent(in) :: b
      character(len=:), allocatable :: str
      character(len=12) :: num
      integer :: r
      if (asm%ngroups == 1) then
        str = 'all ranks, one instance'
      else if (asm%group(b) < 0) then
        str = 'all ranks, shared'
      else
        str = 'rank'
        do r = asm%group(b), n_ranks - 1, asm%ngroups
          write (num, '(i0)') r
          str = str//' '//trim(num)
        end do
      end if
    end function ranks_of

    !> K is block diagonal by body unless the constraints are factorised with it ('saddle')
    logical function split_bodies()
      split_bodies = ls%schur
    end function split_bodies

    subroutine setup_contact()
      allocate (contact)
      call scene_contact(deck, model, contact, use_contact)
      if (.not. use_contact) deallocate (contact)
      ls%schur = .not. use_contact .or. deck%contact%solver == 'schur'
      if (use_contact .and. deck%run%analysis /= 'static') call mass_setup(model, ls%mass, err)
    end subroutine setup_contact

    !> Gravity's acceleration at the start, g on every point of a free body clear of contact
    !> (restrained or resting bodies start at rest, a = 0: their supports hold them). With 0
    !> for a falling body the first step would change its momentum by (gamma - 1/2) m g dt
    !> too much (thesis Newmark: 3e-5 of a bouncing ring's momentum change). (Not M^-1 f for
    !> nodal loads: concentrated at the loaded nodes, it made Newton diverge on a thin strip
    !> under a point load.)
    subroutine start_acceleration()
      logical :: falls(model%nbody)
      integer :: b, n
      if (all(model%gravity == 0)) return
      falls = [(.not. any(model%fixed(dof(model%body(b)%node_first, 1):dof(model%body(b)%node_last, 7))), &
                b=1, model%nbody)]
      if (use_contact) call clear_near_contact(model, st%q, st%qd, deck%run%dt, contact, falls)
      do b = 1, model%nbody
        if (.not. falls(b)) cycle
        do n = model%body(b)%node_first, model%body(b)%node_last
          st%qdd(dof(n, 1):dof(n, 3)) = model%gravity
        end do
      end do
    end subroutine start_acceleration

    !> the output folder and files; the history's per-body and per-pair columns are named
    !> after the bodies and obstacles (targets -k: names from -size(obstacles) up)
    subroutine open_history()
      character(len=64), allocatable :: body_names(:)   ! (the deck's longest name)
      character(len=:), allocatable :: pair_names(:)
      logical :: friction
      body_names = [character(len=64) :: (model%body(k)%name, k=1, model%nbody)]
      friction = .false.
      allocate (character(len=1) :: pair_names(0))
      if (use_contact) then
        friction = deck%run%analysis /= 'static' .and. (any(contact%mu_d > 0) .or. any(contact%mu_s > 0))
        call pair_labels(contact%pair, [character(len=64) :: (deck%obstacles(-k)%name, &
                         k=-size(deck%obstacles), -1), '-', body_names], -size(deck%obstacles), pair_names)
      end if
      call output_open(out, dir, tracked, labels, body_names, pair_names, friction, &
                       moving_obstacles(deck, use_contact), restart_step, st%t, err, folder_of(restart))
    end subroutine open_history

    subroutine history_row(newton)
      integer, intent(in) :: newton
      real(dp) :: lmax
      pen = 0; gmax = 0; lmax = 0
      if (use_contact) then
        call contact_penetration(contact, model, st%q, pen, gmax)
        if (contact%nact > 0) lmax = maxval(contact%act(1:contact%nact)%lambda)
        call output_history(out, st, bal, contact%nact, contact_force_total(contact), newton, &
                            max(pen, 0._dp), rep%neg_pivots, lmax, gmax, &
                            pair_normal_force(contact), pair_active_count(contact), &
                            norm2(contact%impulse, dim=1), err, &
                            pair_tangential_force(contact), sum(contact%friction_work), contact%obstacle_work)
      else
        call output_history(out, st, bal, 0, 0._dp, newton, 0._dp, rep%neg_pivots, 0._dp, 0._dp, &
                            [real(dp) ::], [integer ::], [real(dp) ::], err)
      end if
    end subroutine history_row

    subroutine frame()
      real(dp), allocatable :: fc(:, :), sd(:, :)
      if (.not. deck%output%vtu) return
      if (use_contact) then
        allocate (fc(3, model%nnode), sd(1, model%nnode))
        call contact_nodal_fields(contact, model, fc)
        call contact_signed_distance(contact, model, st%q, sd(1, :))
        call output_frame(out, model, st, [field('contact_force', fc), &
                                           field('signed_distance', sd)], err)
      else
        call output_frame(out, model, st, [field_t ::], err)
      end if
    end subroutine frame

    logical function failed(what)
      character(len=*), intent(in) :: what
      call share_error(err)   ! collective: every rank stops with the same code
      failed = allocated(err)
      if (failed) then
        if (is_root()) write (0, '(a,a,a,a)') 'error (', what, '): ', err%message
        code = exit_solver
        if (what == 'output' .or. what == 'setup' .or. what == 'restart') code = exit_input
        call output_release(out)
      end if
    end function failed

    !> One line per frame: Newton iterations per step and the time left from the frame
    !> interval just done (contact makes later steps dearer than the first ones: from the
    !> start, a run that took 175 s had said 11 s left)
    subroutine progress()
      real(dp) :: now, rate
      integer :: nc
      now = wall_time()
      rate = (now - last%wall)/max(st%t - last%t, tiny(1._dp))
      nc = 0
      if (use_contact) nc = contact%nact
      print '(a,i7,a,es11.4,a,es9.2,a,f5.2,a,i4,a,f8.1,a,f8.1,a)', 'step', st%step, '  t', st%t, &
        '  dt', nm%dt, '  newton/step', real(total_newton - last%newton)/max(st%step - last%step, 1), &
        '  contacts', nc, '  elapsed', now - t0, ' s  left', rate*max(deck%run%t_end - st%t, 0._dp), ' s'
      last = progress_t(now, st%t, st%step, total_newton)
    end subroutine progress

    subroutine checkpoint()
      type(error_t), allocatable :: e
      call ls%drop_factors()   ! on every rank: a restart from here starts with new factors
      call output_flush(out, e)   ! the history up to this step, for a restart from here
      if (.not. allocated(e)) call save_checkpoint(dir//'/checkpoint.h5', model, st, level, contact, e)
      call share_error(e)
      if (allocated(e)) then
        if (is_root()) write (0, '(a,a)') 'error (checkpoint): ', e%message
        code = exit_solver
        call output_release(out)
      end if
    end subroutine checkpoint

    !> The solver cannot go on: keep the last good state (frame and checkpoint) and stop.
    subroutine give_up(why)
      character(len=*), intent(in) :: why
      type(error_t), allocatable :: e
      if (is_root()) write (0, '(a,es12.5,a,a)') 'error: the solver cannot go on at t = ', st%t, &
        ' s: ', why
      call frame()
      call checkpoint()
      call ls%finish()
      call output_close(out, e)
      if (is_root()) write (0, '(a)') 'the last good state is in '//dir// &
        '/checkpoint.h5 (restart with --restart) and in the last frame of '//dir//'/run.pvd'
      ! (a thin hoop bouncing off a dome under the trapezoidal rule: Newton stalled in free
      ! flight after the bounce; gamma 0.6 ran it through, docs/method.md)
      if (is_root() .and. nm%gamma <= 0.5_dp .and. deck%run%analysis /= 'static') write (0, '(a)') &
        'hint: gamma = 0.5 keeps the shells'' fastest vibrations undamped, which can stall Newton; '// &
        'beta = 0.3025, gamma = 0.6 damps them (or the thesis'' beta = 1, gamma = 1.5)'
      code = exit_solver
    end subroutine give_up

    subroutine finish()
      type(error_t), allocatable :: e
      call ls%finish()
      call output_close(out, e)
      call share_error(e)
      if (allocated(e)) then
        if (is_root()) write (0, '(a,a)') 'error (output): ', e%message
        code = exit_solver; return
      end if
      if (deck%output%plots .and. is_root()) then
        call make_plots(dir, e, missing)
        if (allocated(e)) write (0, '(a,a)') 'warning: plots: ', e%message
        if (missing) write (0, '(a)') 'warning: gnuplot is not installed: '//dir// &
          '/plots.gp was written but not run'
      end if
      if (is_root() .and. .not. quiet) then
        print '(a,i0,a,a,a,a)', 'done: ', st%step, ' steps in ', seconds(wall_time() - t0), &
          ' s; results in ', dir
        print '(a)', timer_report(wall_time() - t0)
        if (deck%run%analysis /= 'static' .and. restart_step < 0) then
          print '(a)', balance_summary(bal0, bal, model%length, any(model%fixed) .or. &
                                       any(fext /= 0) .or. any(fgrav /= 0) .or. size(deck%obstacles) > 0)
          print '(a)', energy_balance(bal0, bal, balance_terms(deck, contact))
        end if
      end if
    end subroutine finish

    !> Statics: load steps of the dead loads; one history row and frame per load step
    !> (t = load factor).
    subroutine static_run()
      integer :: i
      do i = 1, deck%run%load_steps
        call static_solve(model, asm, ls, fext, st%t, real(i, dp)/deck%run%load_steps, &
                          deck%run%max_step_cuts, opts, st%q, rep, err, contact)
        if (allocated(err)) then
          call give_up(err%message); return
        end if
        st%t = real(i, dp)/deck%run%load_steps; st%step = i
        call account(model, asm, st, fext*st%t, q0, bal)
        call history_row(rep%iters)
        if (failed('history')) return
        call frame()
        if (failed('frame')) return
        if (is_root() .and. .not. quiet) print '(a,i4,a,f6.3,a,i3)', 'load step', i, &
          '  factor', st%t, '  newton', rep%iters
      end do
      call checkpoint()
      call finish()
    end subroutine static_run
  end subroutine run_deck
  !> The energy balance's terms that the scene has: friction's, moving obstacles'
  function balance_terms(deck, contact) result(terms)
    type(deck_t), intent(in) :: deck
    type(contact_t), intent(in), optional :: contact
    type(energy_term_t), allocatable :: terms(:)
    allocate (terms(0))
    if (.not. present(contact)) return
    if (any(contact%mu_d > 0)) terms = [terms, energy_term_t('dissipated by friction', &
                                                             sum(contact%friction_work))]
    if (moving_obstacles(deck, .true.)) &
      terms = [terms, energy_term_t('taken from moving obstacles', -contact%obstacle_work)]
  end function balance_terms

  logical function moving_obstacles(deck, use_contact)
    type(deck_t), intent(in) :: deck
    logical, intent(in) :: use_contact
    integer :: k
    moving_obstacles = use_contact .and. any([(any(deck%obstacles(k)%velocity /= 0), &
                                               k=1, size(deck%obstacles))])
  end function moving_obstacles
end module casca_run
