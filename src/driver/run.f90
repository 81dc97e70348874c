!> The commands that work on a deck: `check` (read, sanity, build) and `run` (the time loop:
!> step, account, write; the run's state is casca_run_state's run_t, its warnings
!> casca_run_watch's). Exit codes: 0 done, 2 bad input, 3 the solver could not go on.
module casca_run
  use, intrinsic :: iso_fortran_env, only: output_unit
  use casca_kinds, only: dp, pi
  use casca_error, only: error_t
  use casca_deck, only: deck_t, read_deck, unset, add_problem, default_newton_tol, frame_interval
  use casca_sanity, only: check_deck
  use casca_scene, only: build_model, initial_state, tracked_nodes, scene_contact
  use casca_starter, only: put_warnings, spring_time, deck_warnings
  use casca_model, only: model_t, reference_state, dof, follower_loaded
  use casca_assembly, only: assembly_setup
  use casca_mass_solver, only: mass_setup
  use casca_start_acceleration, only: loaded_acceleration
  use casca_newmark, only: state_t, newmark_step
  use casca_statics, only: static_solve, unloaded_inertia
  use casca_time_scheme, only: newmark_scheme, alpha_scheme
  use casca_step_control, only: local_error, depth_error, energy_error, next_step_ratio
  use casca_step_size, only: time_to_contact
  use casca_accounting, only: balance_t, account, gravity_load, balance_summary, &
                              energy_balance, balance_remainder
  use casca_output, only: output_open, output_history, output_frame, output_close, output_mark_stopped, &
                          output_flush, output_release, output_indicator_report
  use casca_vtu_writer, only: field_t, field
  use casca_mesh_indicator, only: indicator_line_len
  use casca_contact, only: contact_t, constraint_t, set_restore
  use casca_contact_active_set, only: contact_update
  use casca_contact_rows, only: contact_force_total, contact_nodal_fields, pair_stored_energy, start_carry
  use casca_contact_probes, only: contact_penetration, contact_signed_distance
  use casca_pair_report, only: pair_normal_force, pair_active_count, pair_labels
  use casca_contact_friction, only: pair_tangential_force
  use casca_checkpoint, only: save_checkpoint, load_checkpoint
  use casca_plots, only: make_plots
  use casca_pair_gaps, only: pair_gap_t, pair_gaps, pair_gaps_at, pair_gap_lines
  use casca_files, only: folder_of
  use casca_stop_request, only: catch_stop_signals, stop_requested, signal_name
  use casca_free_flight, only: idle_bodies, clear_near_contact, advance_idle
  use casca_obstacle, only: obstacle_t, obstacle_point
  use casca_mpi, only: is_root, wall_time, n_ranks, share_error
  use casca_strings, only: count_of, rtoa, ftoa, itoa
  use casca_timers, only: timer_start, timer_stop, timer_report, seconds, t_account, t_output
  use casca_run_state, only: run_t, progress_t, exit_ok, exit_input, exit_solver, exit_signal, cap_hold, easy_hold, &
                             newton_share, newton_floor
  use casca_run_watch, only: watch_energy, watch_stability, watch_thickness, watch_faces, watch_sink, squeezed, squeeze_note, &
                             rest_now, made_judged, warn_at_end, balance_terms, moving_obstacles
  implicit none
  private
  public :: load_scene, run_deck, exit_ok, exit_input

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
    if (deck%nproblems == deck%readable_problems) call check_deck(deck)   ! (the others' values too)
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
        write (0, '(a)') count_of(deck%nproblems, 'problem', 'problems')//' in the deck; nothing was run'
      end if
      code = exit_input
    end if
  contains
    !> bodies of a contact pair that overlap at the start are refused, never ignored: named at
    !> the impactor body's line, or at the obstacle's (a container's body outside it)
    subroutine check_overlap()
      type(contact_t) :: probe
      real(dp), allocatable :: q(:)
      integer :: added, k, worst, t, line
      logical :: found, container
      character(len=:), allocatable :: msg, body, depth, nodes, who
      call scene_contact(deck, model, probe, found)
      if (.not. found) return
      allocate (q(model%ndof))
      call reference_state(model, q)
      call contact_update(probe, model, q, .true., added)
      if (added == 0) return
      worst = minloc(probe%set%act(1:probe%set%nact)%gap, dim=1)
      k = probe%set%act(worst)%node
      t = probe%pair(2, probe%set%act(worst)%pair)
      body = trim(model%body(model%node_body(k))%name)
      depth = 'node '//itoa(k - model%body(model%node_body(k))%node_first + 1)//' is '// &
              rtoa(-probe%set%act(worst)%gap)//' m '
      nodes = ' ('//count_of(added, 'node', 'nodes')//' in all); '
      container = .false.
      if (t > 0) then
        line = deck%bodies(model%node_body(k))%line
        who = 'bodies '''//body//''' and '''//trim(target_name(t))//''''
      else
        line = deck%obstacles(-t)%line
        who = 'body '''//body//''' and &obstacle '''//trim(target_name(t))//''''
        container = deck%obstacles(-t)%inside
      end if
      if (container) then
        msg = '&obstacle '//trim(target_name(t))//' is a container (inside = .true.), and body '''//body// &
              ''' is not inside it at the start: '//depth//'beyond its wall'//nodes// &
              'place the body within its radius, or set inside = .false. to keep it out'
      else
        msg = who//' overlap at the start: '//depth//'inside'//nodes//'move them apart'
      end if
      if (probe%opt%faces) msg = msg//' (contact is between the shell faces: half of each '// &
                                 'thickness from the mid-surface)'
      call add_problem(deck, line, msg)
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

  !> Run the deck at path into out_dir (the deck's folder if '') from t = 0, or from the
  !> checkpoint restart; code: exit_ok, exit_input or exit_solver.
  subroutine run_deck(path, out_dir, restart, quiet, code)
    character(len=*), intent(in) :: path, out_dir, restart
    logical, intent(in) :: quiet
    integer, intent(out) :: code
    type(run_t), allocatable :: r   ! (large: MUMPS structures)
    allocate (r)
    r%quiet = quiet; r%restart = restart; r%kept = restart
    call run_setup(r, path, out_dir)
    if (r%code == exit_ok) then
      if (r%deck%run%analysis == 'static') then
        call static_run(r)
      else
        call dynamic_run(r)
      end if
    end if
    code = r%code
  end subroutine run_deck

  !> Read and build the scene, its contact and equations, the start (t = 0 or the
  !> checkpoint's) and the output folder
  subroutine run_setup(r, path, out_dir)
    type(run_t), intent(inout) :: r
    character(len=*), intent(in) :: path, out_dir
    integer :: k
    real(dp) :: cap(3)   !< the energy's cap on the steps, from a checkpoint
    character(len=300), allocatable :: far(:)
    call catch_stop_signals()   ! (from here a signal stops the run at a step's end, kept)
    call load_scene(path, r%deck, r%model, r%code)
    if (r%code /= exit_ok) return
    if (is_root() .and. .not. r%quiet .and. r%deck%run%title /= '') &
      print '(a)', 'casca: '//trim(r%deck%run%title)
    allocate (r%ls)
    r%dir = trim(r%deck%output%dir)
    if (out_dir /= '') r%dir = trim(out_dir)
    associate (deck => r%deck, model => r%model)
      call setup_contact(r)
      if (failed(r, 'setup')) return
      call assembly_setup(model, r%asm, r%err, split=r%ls%schur)
      if (failed(r, 'setup')) return
      if (deck%run%ordering == 'metis') r%ls%solver%ordering = 1
      r%ls%solver%single = deck%run%factor_precision == 'single'   ! (K only: M stays double)
      r%opts%tol = default_newton_tol
      if (deck%run%newton_tol /= unset) r%opts%tol = deck%run%newton_tol
      r%opts%max_iter = deck%run%newton_max_iter
      r%opts%reuse = deck%run%reuse_factorisation
      r%opts%linear = deck%run%linear
      if (r%opts%linear) then   ! (K0 u = f: the first increment is the answer, whatever it leaves)
        r%opts%tol = 1e100_dp; r%opts%force_tol = 1e100_dp; r%opts%max_iter = 1
      end if
      allocate (r%fext(model%ndof))
      call gravity_load(model, r%fext)
      r%fext = r%fext + model%fext
      call tracked_nodes(deck, model, r%tracked, far)
      if (is_root()) call put_warnings(far, 0)
      if (is_root()) call put_warnings(deck_warnings(deck), 0)
      allocate (r%labels(size(r%tracked)))
      do k = 1, size(r%tracked)
        associate (b => model%body(model%node_body(r%tracked(k))))
          write (r%labels(k), '(a,a,i0,a,3(g0.4,:,", "))') trim(b%name), ' node ', &
            r%tracked(k) - b%node_first + 1, ' near (', deck%output%track(:, k)
        end associate
        r%labels(k) = trim(r%labels(k))//')'
      end do
      call initial_state(deck, model, r%st)
      allocate (r%q0(model%ndof))
      call reference_state(model, r%q0)
      if (r%restart /= '') then   ! (statics: t is the load factor, <= 1)
        call load_checkpoint(r%restart, model, merge(1._dp, deck%run%t_end, deck%run%analysis == &
                             'static'), deck%run%max_step_cuts, r%st, r%level, r%err, r%contact, &
                             r%dt_try, cap, r%bal%path_work)
        if (failed(r, 'restart')) return
        r%bal%q_path = r%st%q   ! (the open pressures' and moments' work goes on from here)
        r%dt_cap = cap(1); r%cap_since = cap(2); r%made_last = cap(3)
        r%restart_step = r%st%step
      end if
    end associate
    call open_history(r)
    if (failed(r, 'output')) return
    r%t0 = wall_time()
  end subroutine run_setup

  !> The time loop: a Newmark step (halved when it fails, grown back when Newton is at ease),
  !> the idle bodies' exact advance, the balance, the history row, frames and checkpoints
  subroutine dynamic_run(r)
    type(run_t), intent(inout) :: r
    real(dp) :: interval, next_frame, next_ckpt
    real(dp), allocatable :: q_before(:), qd_before(:)
    type(state_t) :: st_before
    type(contact_t), allocatable :: contact_before
    type(balance_t) :: bal_before
    real(dp) :: rest, made
    !> a step that makes more energy than this share of what the bodies hold is taken again
    !> with half the step (as one where Newton fails): the schemes keep or remove the energy
    !> of linear vibrations, so it is the contact's doing or a motion the step cannot follow;
    !> a tenth of this share is still warned of at the end (warn_energy). With a tolerance,
    !> free steps are held to a tighter share (energy_accepted)
    real(dp), parameter :: made_limit = 1e-2_dp
    !> guarded: the balance is exact step by step (not so for the work of moving obstacles,
    !> counted as their velocity times the step's impulse, nor for pressures on open
    !> surfaces, summed along the straight segment between the states, not at the scheme's
    !> force level); energy_cut: this step was cut for its energy once already (a half step that
    !> makes energy too is kept: a shorter one made more on a plane pushing a ring)
    logical :: guarded, energy_cut
    integer :: sig
    character(len=:), allocatable :: why
    call dynamic_start(r, interval, next_frame, next_ckpt)
    if (r%code /= exit_ok) return
    associate (deck => r%deck, model => r%model, st => r%st, nm => r%nm, rep => r%rep)
      guarded = .not. (moving_obstacles(deck, allocated(r%contact)) .or. any(model%pressure /= 0))
      energy_cut = .false.
      do while (st%t < deck%run%t_end - 1e-6_dp*deck%run%dt)
        nm%dt = step_length(r, interval)
        if (deck%run%skip_idle_bodies) call update_frozen(r)
        if (allocated(r%err)) then
          call give_up(r, r%err%message); return
        end if
        q_before = st%q; qd_before = st%qd
        st_before = st   ! (to take the step again)
        bal_before = r%bal
        if (allocated(r%contact)) contact_before = r%contact
        call newmark_step(model, r%asm, r%ls, nm, r%fext, r%opts, st, rep, r%err, r%contact)
        if (allocated(r%err)) then
          if (saddle_instead()) then   ! (the same step, the constraints in the factorised matrix)
            call undo_step()
            deallocate (r%err)
            cycle
          end if
          if (may_cut()) then
            call cut_step(r%err%message)   ! (the state is unchanged)
            deallocate (r%err)
            cycle
          end if
          if (r%onset .and. .not. r%over_onset) then
            ! (a thin hoop hopping on a floor under a tolerance: a 5.1 us step up to a node's
            ! landing failed and could not be halved at 0.187 s; steps over it went on)
            r%over_onset = .true.
            deallocate (r%err)
            cycle
          end if
          call give_up(r, r%err%message)
          return
        end if
        if (r%sc%tol > 0) then
          if (.not. step_accepted(r, st_before)) then
            call undo_step()
            cycle
          end if
        end if
        if (any(r%idle)) call advance_idle(model, r%idle, nm%dt, q_before, qd_before, st%q, st%qd, st%qdd)
        call timer_start(t_account)
        call account_state(r)
        call timer_stop(t_account)
        rest = rest_now(r)
        made = r%rest_last - rest
        if (r%sc%tol > 0 .and. guarded) then
          if (in_contact()) then
            r%dt_cap = huge(1._dp); r%made_last = 0
          else
            if (.not. energy_accepted(r, made_judged(r, made), energy_scale())) then
              call undo_step()
              cycle
            end if
          end if
        end if
        if (guarded .and. .not. energy_cut .and. made_judged(r, made) > made_limit*energy_scale() .and. &
            may_cut()) then
          why = 'the step made '//ftoa(100*made/energy_scale())//'% of the energy the '// &
                'bodies hold (a node deep into a target, or a mode the step cannot follow)'
          call undo_step()   ! (after the share: undone, the step's end is its start)
          call cut_step(why)
          energy_cut = .true.
          cycle
        end if
        energy_cut = .false.; r%over_onset = .false.
        r%ls%saddle_steps = max(r%ls%saddle_steps - 1, 0)
        r%total_newton = r%total_newton + rep%iters
        if (r%sc%tol > 0) then
          r%level = 0
        else if (r%level > 0 .and. rep%iters <= 3) then
          r%level = r%level - 1   ! Newton is at ease: grow back
        end if
        call watch_energy(r, rest, contact_before, st_before%h_last)
        call watch_thickness(r)
        if (.not. step_written(r, interval, next_frame, next_ckpt)) return
        sig = stop_requested()
        if (sig > 0) then
          call stop_on_request(r, sig); return
        end if
      end do
    end associate
    call checkpoint(r)
    if (r%code /= exit_ok) return
    call finish(r)
  contains
    !> retry from the step's start with half the step
    subroutine cut_step(why)
      character(len=*), intent(in) :: why
      r%level = r%level + 1
      r%dt_try = r%nm%dt/2
      if (is_root() .and. .not. r%quiet) print '(a,es10.3,a,a)', 'step cut to dt = ', &
        merge(r%dt_try, r%deck%run%dt/2**r%level, r%sc%tol > 0), ': ', why
    end subroutine cut_step

    !> solver = 'auto' on the Schur path, whose S was singular: K near-singular where the
    !> constraints hold it (S's largest eigenvalues blow up) looks like dependent rows; the
    !> saddle-point matrix is regular there, so the step is taken again with it, and the next
    !> saddle_hold steps too
    logical function saddle_instead()
      integer, parameter :: saddle_hold = 20
      saddle_instead = r%ls%auto .and. r%ls%schur .and. r%ls%saddle_steps == 0 .and. &
                       r%asm%ngroups == 1 .and. index(r%err%message, 'singular Schur complement') > 0
      if (.not. saddle_instead) return
      r%ls%saddle_steps = saddle_hold + 1
      if (is_root() .and. .not. r%quiet) print '(a)', 'step taken again with the whole saddle-point '// &
        'matrix: '//r%err%message
    end function saddle_instead

    !> the step may be halved again: at most max_step_cuts times in a row, and with the error
    !> control not below its shortest step halved as often again (accepted slivers between
    !> the cuts start the count anew: a ring crushed past what its mesh can fold cut its step
    !> down to 1.5e-11 s, where the grid's count of steps overflowed)
    logical function may_cut()
      may_cut = r%level < r%deck%run%max_step_cuts
      if (r%sc%tol > 0) may_cut = may_cut .and. r%nm%dt/2 >= r%sc%dt_min/2**r%deck%run%max_step_cuts
    end function may_cut

    subroutine undo_step()
      r%st = st_before; r%bal = bal_before
      if (allocated(r%contact)) r%contact = contact_before
    end subroutine undo_step

    !> a contact active at the step's start or end (its energy has the cut above instead)
    logical function in_contact()
      in_contact = .false.
      if (allocated(r%contact)) in_contact = r%contact%set%nact > 0 .or. contact_before%set%nact > 0
    end function in_contact

    !> what the bodies hold (kinetic and strain energy) or the loads did, before or after
    !> the step: within a step, so that a restart judges its steps as the run it continues
    real(dp) function energy_scale()
      energy_scale = max(bal_before%kinetic + bal_before%strain, r%bal%kinetic + r%bal%strain, &
                         abs(bal_before%work), abs(r%bal%work))
    end function energy_scale
  end subroutine dynamic_run

  !> Before the first step: the scheme, the error control, the first frame and history row
  !> (or, at a restart, the energy the first step is judged from), the opening lines, and the
  !> next frame's and checkpoint's times
  subroutine dynamic_start(r, interval, next_frame, next_ckpt)
    type(run_t), intent(inout) :: r
    real(dp), intent(out) :: interval, next_frame, next_ckpt
    real(dp) :: dt
    integer :: k
    associate (deck => r%deck, model => r%model, st => r%st, nm => r%nm)
      if (deck%run%rho_inf /= unset) then
        nm = alpha_scheme(deck%run%rho_inf)
      else
        nm = newmark_scheme(deck%run%beta, deck%run%gamma)
      end if
      dt = deck%run%dt
      if (deck%run%tolerance /= unset) then
        r%sc%tol = deck%run%tolerance
        r%sc%length = model%length
        if (deck%run%tolerance_length /= unset) r%sc%length = deck%run%tolerance_length
        ! (a hair over: a step ended on the grid is a difference of times, rounded above it,
        ! and a step at the shortest that was still judged too long was taken again for ever:
        ! two balls glancing with skip_idle_bodies = .false. hung at 2.7875 ms)
        r%sc%dt_min = dt/2**deck%run%max_step_cuts*(1 + 1e-9_dp)
        ! Newton's tolerance: the deck's, and at most newton_share of the error asked for.
        ! Its error is left in every step, of one sign and 2/dt of it in the velocity under
        ! the midpoint rule, and more steps carry more of it: a free hoop spinning at
        ! tolerance = 1e-5 was further off its circle than at 1e-3 (1.4e-5 against 6.8e-7
        ! m, L lost 5.3e-5) with 1e-9; 1e-10 keeps it to 1.3e-7 m and L to 1.6e-8. (A
        ! thousandth of the step's error, tried before, lost 2.5% of a spinning ring's L.)
        if (deck%run%newton_tol == unset) r%opts%tol = min(r%opts%tol, &
          max(newton_floor, newton_share*r%sc%tol*r%sc%length/model%length))
        if (r%dt_try == 0) r%dt_try = dt
      end if
      interval = frame_interval(deck)
      next_frame = next_multiple(st%t, interval)
      next_ckpt = huge(1._dp)
      if (deck%output%checkpoint_interval > 0) &
        next_ckpt = next_multiple(st%t, deck%output%checkpoint_interval)
      if (r%restart_step < 0) then
        call start_acceleration(r)
        if (failed(r, 'start acceleration')) return
        call account_state(r)
        r%bal0 = r%bal
        call watch_energy(r, rest_now(r))
        if (.not. row_and_frame(r, 0)) return
      else   ! (the energy before the first step, for the first step's check)
        call account_state(r)
        r%rest_last = rest_now(r)
      end if
      if (is_root() .and. .not. r%quiet) print '(a)', 'casca: '//count_of(model%nbody, 'body', 'bodies')// &
        ', '//count_of(model%nelem, 'element', 'elements')//', '// &
        count_of(r%asm%neq_total, 'unknown', 'unknowns')//', '//count_of(n_ranks, 'rank', 'ranks')
      if (is_root() .and. .not. r%quiet .and. n_ranks > 1) print '(a,*(a,:,"; "))', &
        'casca: bodies solved on ', (trim(model%body(k)%name)//': '//ranks_of(r, k), k=1, model%nbody)
      r%last = progress_t(r%t0, st%t, st%step, 0)
      allocate (r%frozen(model%ndof), r%idle(model%nbody))
      r%frozen = .false.; r%idle = .false.
    end associate
  end subroutine dynamic_start

  !> After an accepted step: its history row, the frame and progress line when one is due,
  !> the checkpoint when one is due. False when the run must stop (r%code says why).
  logical function step_written(r, interval, next_frame, next_ckpt) result(ok)
    type(run_t), intent(inout) :: r
    real(dp), intent(in) :: interval
    real(dp), intent(inout) :: next_frame, next_ckpt
    real(dp) :: dt
    ok = .false.
    dt = r%deck%run%dt
    call timer_start(t_output)
    call history_row(r, r%rep%iters)
    call timer_stop(t_output)
    if (failed(r, 'history')) return
    if (r%st%t >= next_frame - 1e-6_dp*dt .or. r%st%t >= r%deck%run%t_end - 1e-6_dp*dt) then
      call watch_faces(r)
      call timer_start(t_output)
      call frame(r)
      call timer_stop(t_output)
      if (failed(r, 'frame')) return
      next_frame = next_frame + interval
      if (is_root() .and. .not. r%quiet) call progress(r)
    end if
    if (r%st%t >= next_ckpt - 1e-6_dp*dt) then
      call checkpoint(r)
      if (r%code /= exit_ok) return
      next_ckpt = next_ckpt + r%deck%output%checkpoint_interval
    end if
    ok = .true.
  end function step_written

  !> Statics: load steps of the dead loads; one history row and frame per load step
  !> (t = load factor), a checkpoint at every multiple of checkpoint_interval (of the load
  !> factor); a restart goes on from the checkpoint's load step. A linear analysis is one
  !> step, one solve.
  subroutine static_run(r)
    type(run_t), intent(inout) :: r
    integer :: i, stabilised, sig, nsteps
    real(dp) :: next_ckpt
    real(dp), allocatable :: q_start(:)
    type(constraint_t), allocatable :: act_start(:)
    associate (deck => r%deck, st => r%st)
      nsteps = merge(1, deck%run%load_steps, deck%run%linear)
      next_ckpt = huge(1._dp)
      if (deck%output%checkpoint_interval > 0) &
        next_ckpt = next_multiple(st%t, deck%output%checkpoint_interval)
      if (st%step == 0) then   ! (the unloaded state, as a dynamic run's t = 0: frames and plots start undeformed)
        call account_state(r, factor=0._dp)
        if (.not. row_and_frame(r, 0)) return
        if (.not. r%opts%linear) then   ! (the first load step's inertia is judged against it)
          if (unloaded_inertia(r%model, r%asm, r%ls, r%fext, r%opts, st%q, r%contact) == 0) &
            r%stability%t_before = 0
        end if
      end if
      do i = st%step + 1, nsteps
        q_start = st%q
        if (allocated(r%contact)) act_start = r%contact%set%act(1:r%contact%set%nact)
        call static_solve(r%model, r%asm, r%ls, r%fext, st%t, real(i, dp)/nsteps, &
                          deck%run%max_step_cuts, r%opts, st%q, r%rep, r%err, stabilised, r%contact)
        if (allocated(r%err)) then
          if (stop_requested() > 0) then   ! (the step under way abandoned: the last converged kept)
            st%q = q_start
            if (allocated(r%contact)) call set_restore(r%contact%set, act_start)
          end if
          call give_up(r, r%err%message); return   ! (which stops for the signal)
        end if
        st%t = real(i, dp)/nsteps; st%step = i
        call account_state(r, factor=st%t)   ! (issue 17)
        call watch_stability(r, stabilised > 0)
        call watch_thickness(r)
        call watch_faces(r)
        if (.not. row_and_frame(r, r%rep%iters)) return
        if (is_root() .and. .not. r%quiet) print '(a,i4,a,f6.3,a,i3,a)', 'load step', i, &
          '  factor', st%t, '  newton', r%rep%iters, &
          trim(merge('  stabilised', '            ', stabilised > 0))
        sig = stop_requested()
        if (sig > 0 .and. i < nsteps) then
          call stop_on_request(r, sig); return
        end if
        if (st%t >= next_ckpt - 1e-9_dp .and. i < nsteps) then
          call checkpoint(r)
          if (r%code /= exit_ok) return
          next_ckpt = next_multiple(st%t, deck%output%checkpoint_interval)
        end if
      end do
    end associate
    call checkpoint(r)
    call finish(r)
  end subroutine static_run

  !> The next step: the deck's dt halved level times, or with the error control the frame
  !> interval halved as often as dt_try asks, on that length's grid from t = 0 (a step off
  !> the grid, after a landing, first returns to it): the steps of a level follow each other
  !> with the same factors and land on every frame. A step is ended at the predicted time of
  !> first contact.
  real(dp) function step_length(r, interval) result(h)
    type(run_t), intent(inout) :: r
    real(dp), intent(in) :: interval
    real(dp) :: hit, to_grid
    associate (st => r%st, t_end => r%deck%run%t_end)
      if (r%sc%tol <= 0) then
        h = r%deck%run%dt/2**r%level
        ! off its own grid (grown back after a cut): to the grid, so that the steps land on the
        ! deck's dt again and the frames on their times (on it: h itself, as a restart does)
        to_grid = next_multiple(st%t, h) - st%t
        if (to_grid < (1 - 1e-6_dp)*h) h = to_grid
        h = to_end(h)
        return
      end if
      h = to_end(next_multiple(st%t, level(min(r%dt_try, (1 - 1e-6_dp)*r%dt_cap))) - st%t)
      r%onset = .false.
      if (.not. allocated(r%contact)) return
      r%contact%time = st%t
      hit = time_to_contact(r%contact, r%model, st%q, st%qd, h)
      if (hit <= r%sc%dt_min) then
        ! touching at the start (the last step ended on it): no sliver of a landing, which would
        ! stop the node within it (a force m v / sliver), but the deck's dt from here
        h = min(h, level(r%deck%run%dt))
        r%onset = .true.
      else if (hit < h .and. .not. r%over_onset) then
        h = hit
        r%onset = .true.
      end if
    end associate
  contains
    !> h, or the time left when it is shorter by more than round-off: a step that ends within
    !> 1e-6 h of t_end is h itself, as in a longer run (a run ended there and restarted from
    !> its last checkpoint took a last step an ulp short, and parted from the longer run
    !> by 1e-14, then 9e-7 of the kinetic energy where a kept factorisation's test flipped)
    real(dp) function to_end(h0)
      real(dp), intent(in) :: h0
      to_end = h0
      if (r%deck%run%t_end - r%st%t < (1 - 1e-6_dp)*h0) to_end = r%deck%run%t_end - r%st%t
    end function to_end

    !> the frame interval over the power of 2 that makes it at most x
    real(dp) function level(x)
      real(dp), intent(in) :: x
      level = interval/2._dp**max(0, ceiling(log(interval/x)/log(2._dp) - 1e-9_dp))
    end function level
  end function step_length

  !> The first multiple of h after t (t within 1e-6 h of a multiple is on it, as the frames
  !> are: t is a sum of steps, and its rounding grows with their number): frames,
  !> checkpoints and the grid of step lengths
  pure real(dp) function next_multiple(t, h)
    real(dp), intent(in) :: t, h
    next_multiple = (aint(t/h + 1e-6_dp) + 1)*h   ! (aint: t/h may pass huge(1), t >= 0)
  end function next_multiple

  !> With the error control: is the step just taken within the tolerance (or at the shortest
  !> step)? Sets the next step's length.
  logical function step_accepted(r, before) result(ok)
    type(run_t), intent(inout) :: r
    type(state_t), intent(in) :: before
    real(dp) :: err, ratio, h
    logical, allocatable :: skip(:)
    h = r%nm%dt
    ! the nodes of the hard contacts at the step's end (impactor and target element) are left
    ! out: their acceleration follows the contact force, which jumps where it starts, and
    ! their velocity is the correction's; a contact that ended within the step counts (when
    ! it ended is within the step's error). A compliant contact's force follows its gap: its
    ! nodes are judged as any other
    allocate (skip(r%model%nnode))
    skip = .false.
    if (allocated(r%contact)) then
      if (.not. r%contact%opt%compliant) call touching(r%contact)
    end if
    err = local_error(r%sc, r%nm, r%model, before%qdd, r%st%qdd, skip)
    if (allocated(r%contact)) then
      if (r%contact%opt%compliant) err = max(err, compliant_error(r%contact))
    end if
    ratio = next_step_ratio(r%sc, err)
    ok = err <= 1 .or. h <= r%sc%dt_min
    if (err > 1.25_dp .and. ok .and. .not. r%floor_told) then
      ! (once, and clearly above: the answer is then the shortest step's, not the tolerance's)
      r%floor_told = .true.
      if (is_root()) write (0, '(a)') 'warning: the step of '//rtoa(h)//' s to t = '//rtoa(r%st%t)// &
        ' s is '//rtoa(err)//' times the tolerance, at the shortest step allowed (the output interval '// &
        'halved until it is at most dt / 2^max_step_cuts = '//rtoa(r%sc%dt_min)//' s), and was kept: the '// &
        'tolerance is not met there; give a shorter dt or a larger max_step_cuts (&run) for it'
    end if
    if (ok .and. ratio >= 1) then   ! (a step cut short by a frame or the grid does not shorten it)
      r%dt_try = max(r%dt_try, h*ratio)
    else
      r%dt_try = max(h*ratio, r%sc%dt_min)
    end if
    ! the step after a contact's onset is the deck's dt at most, grown again as the error allows
    if (r%onset) r%dt_try = min(r%dt_try, r%deck%run%dt)
  contains
    !> mark the nodes of c's active constraints: the impactor's and its target element's
    subroutine touching(c)
      type(contact_t), intent(in) :: c
      integer :: k
      do k = 1, c%set%nact
        skip(c%set%act(k)%node) = .true.
        if (c%set%act(k)%elem > 0) skip(r%model%conn(:, c%set%act(k)%elem)) = .true.
      end do
    end subroutine touching

    !> depth_error of each pair in compliant contact: its constraints' normal acceleration
    !> changes (the node's less its target point's) and depths, each weighted by its spring
    !> k A_n, so that the pair's force is judged (the vibrations of a plate's nodes on their
    !> springs, which move no force overall, held a plate landing flat to the shortest step),
    !> and its contact time pi sqrt(rho h / k). A depth is the gap's, or the one its normal
    !> speed v would reach on the spring, v sqrt(rho h / k), where deeper (in the step a node
    !> comes in it is still a sliver)
    real(dp) function compliant_error(c) result(e)
      type(contact_t), intent(in) :: c
      real(dp) :: change(c%npairs), depth(c%npairs), tc(c%npairs), da(3), dv(3), w, tb
      integer :: k, j, i
      change = 0; depth = 0; tc = 0
      do k = 1, c%set%nact
        associate (a => c%set%act(k), b => r%model%body(r%model%node_body(c%set%act(k)%node)))
          i = dof(a%node, 1)
          da = r%st%qdd(i:i + 2) - before%qdd(i:i + 2)
          dv = r%st%qd(i:i + 2)
          if (a%elem > 0) then
            do j = 1, size(r%model%conn, 1)
              i = dof(r%model%conn(j, a%elem), 1)
              da = da - a%shp(j)*(r%st%qdd(i:i + 2) - before%qdd(i:i + 2))
              dv = dv - a%shp(j)*r%st%qd(i:i + 2)
            end do
          else if (c%pair(2, a%pair) < 0) then
            dv = dv - c%obstacle(-c%pair(2, a%pair))%velocity
          end if
          w = 1/c%opt%compliance(a%node)
          change(a%pair) = change(a%pair) + w*dot_product(a%n, da)
          tb = spring_time(b, r%deck%contact%stiffness)   ! (pi / omega on the spring)
          depth(a%pair) = depth(a%pair) + w*max(-a%gap, abs(dot_product(a%n, dv))*tb/pi)
          tc(a%pair) = max(tc(a%pair), tb)
        end associate
      end do
      e = depth_error(r%sc, r%nm, change, depth, tc)
    end function compliant_error
  end function step_accepted

  !> Whether the step's energy is within the tolerance while no contact is active
  !> (casca_step_control's energy_error): if not, it is taken again shorter, and later steps
  !> are shorter too (dt_cap); if so, the next step is no longer than the energy allows.
  !> What the step before removed is credited: a body vibrating after its release makes and
  !> removes energy in turn under generalized-alpha, whose K + S is not its conserved energy,
  !> and judged alone its steps fell to 0.78 us where 50 us kept the error (a ring thrown
  !> onto a compliant floor at tolerance 1e-5: 210 steps, 150 of them after the bounce; 89
  !> with the credit, its velocity's error the same)
  logical function energy_accepted(r, made, scale) result(ok)
    type(run_t), intent(inout) :: r
    real(dp), intent(in) :: made, scale
    real(dp) :: err, ratio, h
    h = r%nm%dt
    err = energy_error(r%sc, made + min(0._dp, r%made_last), scale)
    ratio = next_step_ratio(r%sc, err)
    ok = err <= 1 .or. h <= r%sc%dt_min
    if (ok) r%made_last = made
    if (.not. ok) then
      r%dt_try = max(h*ratio, r%sc%dt_min)
      r%dt_cap = h   ! (it would be tried again as soon as a shorter one makes little)
      r%cap_since = r%st%t
    else
      if (ratio < r%sc%grow) r%dt_try = min(r%dt_try, max(h*ratio, r%sc%dt_min))
      ! the cap doubles after cap_hold of its lengths: a step too long once (a load applied
      ! at rest) does not hold the run to it (a cantilever took 6,375 steps at every tolerance,
      ! 25 times the fixed step of its error), and where the energy does limit the steps one
      ! in about cap_hold is retried (a cap growing a little at every step retried one step
      ! in two on a spinning ring, whose energy error is not smooth in the step); after
      ! easy_hold at a step that removed energy: a cap left by a sudden load's first steps
      ! held a strip to an eighth of the step its error allowed for 40 steps, and a tolerance
      ! of 1e-3 took more steps than 1e-4 (92 against 42)
      if (r%dt_cap < huge(1._dp) .and. (r%st%t - r%cap_since >= cap_hold*r%dt_cap .or. &
          (err <= 0 .and. r%st%t - r%cap_since >= easy_hold*r%dt_cap))) then
        r%dt_cap = 2*r%dt_cap; r%cap_since = r%st%t
      end if
    end if
  end function energy_accepted

  !> Leave the bodies that need no solving this step out of the equations (re-analysed
  !> only when that set changes).
  subroutine update_frozen(r)
    type(run_t), intent(inout) :: r
    logical, allocatable :: fz(:)
    integer :: b
    associate (model => r%model, st => r%st)
      if (allocated(r%contact)) r%contact%time = st%t
      call idle_bodies(model, st%q, st%qd, st%qdd, r%fext, r%nm%dt, r%idle, r%contact)
      allocate (fz(model%ndof))
      fz = .false.
      do b = 1, model%nbody
        if (r%idle(b)) fz(dof(model%body(b)%node_first, 1):dof(model%body(b)%node_last, 7)) = .true.
      end do
      if (all(fz .eqv. r%frozen)) return
      r%frozen = fz
      call assembly_setup(model, r%asm, r%err, r%frozen, r%ls%schur)
      call r%ls%new_pattern()
    end associate
  end subroutine update_frozen

  !> The ranks that factorise and solve body b's block (when every body is solved)
  function ranks_of(r, b) result(str)
    type(run_t), intent(in) :: r
    integer, intent(in) :: b
    character(len=:), allocatable :: str
    character(len=12) :: num
    integer :: k
    if (r%asm%ngroups == 1) then
      str = 'all ranks, one instance'
    else if (r%asm%group(b) < 0) then
      str = 'all ranks, shared'
    else
      str = 'rank'
      do k = r%asm%group(b), n_ranks - 1, r%asm%ngroups
        write (num, '(i0)') k
        str = str//' '//trim(num)
      end do
    end if
  end function ranks_of

  !> The deck's contact (none: r%contact stays unallocated); K is block diagonal by body
  !> unless the constraints are factorised with it ('saddle', and 'auto' in statics)
  subroutine setup_contact(r)
    type(run_t), intent(inout) :: r
    logical :: use_contact
    allocate (r%contact)
    call scene_contact(r%deck, r%model, r%contact, use_contact)
    if (.not. use_contact) deallocate (r%contact)
    ! (statics: a body held by its contacts alone leaves K singular, not the saddle matrix)
    r%ls%auto = use_contact .and. r%deck%contact%solver == 'auto' .and. r%deck%run%analysis /= 'static'
    r%ls%schur = .not. use_contact .or. r%deck%contact%solver == 'schur' .or. r%ls%auto
    if (use_contact .and. r%deck%run%analysis /= 'static') call mass_setup(r%model, r%ls%mass, r%err)
  end subroutine setup_contact

  !> The acceleration at the start: the body's g on every point of a free body clear of
  !> contact under gravity alone, the equation of motion's M^-1 (F - f_int - f_p) on a body
  !> clear of contact that carries a load (casca_start_acceleration). Bodies held by their
  !> contacts (start_holds) start at a = 0: under gravity their contacts carry their weight
  !> from the start (start_carry). With 0 for a falling body the first step would change its
  !> momentum by (gamma - 1/2) m g dt too much (thesis Newmark: 3e-5 of a bouncing ring's
  !> momentum change).
  subroutine start_acceleration(r)
    type(run_t), intent(inout) :: r
    logical, dimension(r%model%nbody) :: falls, held, ground, loaded, moves
    logical, allocatable :: near(:)
    integer :: b, n, k
    associate (model => r%model, st => r%st)
      do b = 1, model%nbody
        associate (bd => model%body(b))
          ground(b) = any(model%fixed(dof(bd%node_first, 1):dof(bd%node_last, 7)))
          falls(b) = any(bd%gravity /= 0) .and. .not. ground(b)
          loaded(b) = any(model%fext(dof(bd%node_first, 1):dof(bd%node_last, 7)) /= 0) .or. &
                      follower_loaded(model, b)
        end associate
      end do
      if (allocated(r%contact)) then
        moves = falls .or. loaded
        allocate (near(r%contact%npairs))
        call clear_near_contact(model, st%q, st%qd, r%deck%run%dt, r%contact, moves, near)
        if (any(near)) then   ! (the exact gaps only where the bounding boxes are near)
          call start_holds(r, ground, loaded, near)
          moves = falls .or. loaded
          do k = 1, size(near)
            if (.not. near(k)) cycle
            moves(r%contact%pair(1, k)) = .false.
            if (r%contact%pair(2, k) > 0) moves(r%contact%pair(2, k)) = .false.
          end do
        end if
        held = falls .and. .not. moves   ! (under gravity, free, touching a contact)
        falls = falls .and. moves
        loaded = loaded .and. moves
        r%held_at_start = any(held)
        r%held_g2 = sum(model%body(:)%mass*[(sum(model%body(b)%gravity**2), b=1, model%nbody)], mask=held)
        if (r%held_at_start) call start_carry(r%contact, near, -weights(model, held), ground)
      end if
      do b = 1, model%nbody
        if (.not. falls(b)) cycle
        do n = model%body(b)%node_first, model%body(b)%node_last
          st%qdd(dof(n, 1):dof(n, 3)) = model%body(b)%gravity
        end do
      end do
      if (.not. any(loaded)) return
      if (allocated(r%contact)) then
        call loaded_acceleration(model, r%asm, st%q, r%fext, loaded, st%qdd, r%err, r%ls%mass)
      else
        call loaded_acceleration(model, r%asm, st%q, r%fext, loaded, st%qdd, r%err)
      end if
    end associate
  end subroutine start_acceleration

  !> Of the pairs near at the start, those that hold their bodies from the start (near, on
  !> return). A pair's touching nodes are constraints from the first step where it touches
  !> (a gap within the contact tolerance: a ring 0.5 mm above a floor, within the search
  !> band, was held, its momentum (gamma - 1) m g dt off for the fall), is not parting (the
  !> closest node's closing speed) and, an obstacle, is under the body's weight (it pushes
  !> along its normal; a body with other loads is left held); found only once they
  !> penetrated past the tolerance, the nodes of a plate laid on a floor sank, and the step
  !> that pushed them back left its mid-surface rising (the correction stops the faces,
  !> largely through the fibres' light inertia): it bounced, making energy. Such a pair
  !> holds its bodies where it is grounded too, by touching pairs, on an obstacle or a
  !> restrained body: a plate touching a ceiling, a ring thrown up off a floor and two
  !> touching rings falling together were held at a = 0, their first step 0.5 M a dt off,
  !> booked on the pair.
  subroutine start_holds(r, ground, loaded, near)
    type(run_t), intent(inout) :: r
    logical, intent(in) :: ground(:), loaded(:)
    logical, intent(inout) :: near(:)
    type(pair_gap_t), allocatable :: pg(:)
    logical :: grounded(size(ground)), changed
    real(dp) :: nrm(3), d
    integer :: k, i, j, added
    associate (model => r%model, c => r%contact, st => r%st)
      pg = pair_gaps_at(c, model, st%q, st%qd, horizon=0._dp)
      near = near .and. pg%gap <= c%opt%tol .and. pg%speed >= 0
      do k = 1, c%npairs
        i = c%pair(1, k); j = c%pair(2, k)
        if (.not. near(k) .or. j > 0 .or. loaded(i)) cycle
        call obstacle_point(c%obstacle(-j), c%time, st%q(dof(pg(k)%node, 1):dof(pg(k)%node, 3)), nrm, d)
        near(k) = dot_product(nrm, model%body(i)%gravity) < 0
      end do
      grounded = ground
      changed = .true.
      do while (changed)
        changed = .false.
        do k = 1, c%npairs
          if (.not. near(k)) cycle
          i = c%pair(1, k); j = c%pair(2, k)
          if (j <= 0) then
            changed = changed .or. .not. grounded(i)
            grounded(i) = .true.
          else if (grounded(i) .neqv. grounded(j)) then
            grounded(i) = .true.; grounded(j) = .true.; changed = .true.
          end if
        end do
      end do
      if (any(near)) call contact_update(c, model, st%q, .true., added, touching=near)
      do k = 1, c%npairs   ! (touching, they meet from the first step; held where grounded)
        if (near(k)) near(k) = grounded(c%pair(1, k))
      end do
    end associate
  end subroutine start_holds

  !> (3, nbody): the weight of each body of which, M g on its positions (the consistent mass's
  !> Y-Y entries summed, the momentum's metric), 0 for the others
  pure function weights(model, which) result(w)
    type(model_t), intent(in) :: model
    logical, intent(in) :: which(:)
    real(dp) :: w(3, model%nbody)
    integer :: b, e
    w = 0
    do b = 1, model%nbody
      if (.not. which(b)) cycle
      do e = model%body(b)%elem_first, model%body(b)%elem_last
        w(:, b) = w(:, b) + model%body(b)%gravity*sum(model%emass(1:10, 1:10, e))
      end do
    end do
  end function weights

  !> the output folder and files; the history's per-body and per-pair columns are named
  !> after the bodies and obstacles (targets -k: names from -size(obstacles) up)
  subroutine open_history(r)
    type(run_t), intent(inout) :: r
    character(len=64), allocatable :: body_names(:), sides(:)   ! (the deck's longest name)
    character(len=:), allocatable :: pair_names(:)
    logical :: friction, compliant
    integer :: k, no
    associate (deck => r%deck, model => r%model)
      allocate (body_names(model%nbody))
      do k = 1, model%nbody
        body_names(k) = model%body(k)%name
      end do
      friction = .false.; compliant = .false.
      allocate (character(len=1) :: pair_names(0))
      if (allocated(r%contact)) then
        friction = any(r%contact%mu_d > 0) .or. any(r%contact%mu_s > 0)
        compliant = r%contact%opt%compliant
        no = size(deck%obstacles)
        allocate (sides(no + 1 + model%nbody))   ! (sides -no .. nbody)
        do k = 1, no
          sides(k) = deck%obstacles(no + 1 - k)%name
        end do
        sides(no + 1) = '-'
        sides(no + 2:) = body_names
        call pair_labels(r%contact%pair, sides, -no, pair_names)
      end if
      call output_open(r%out, r%dir, r%tracked, r%labels, body_names, pair_names, friction, &
                       moving_obstacles(deck, allocated(r%contact)), compliant, r%restart_step, r%st%t, &
                       r%err, folder_of(r%restart))
    end associate
  end subroutine open_history

  subroutine history_row(r, newton)
    type(run_t), intent(inout) :: r
    integer, intent(in) :: newton
    real(dp) :: lmax, pen, gmax
    integer :: node
    pen = 0; gmax = 0; lmax = 0
    if (allocated(r%contact)) then
      associate (c => r%contact)
        call contact_penetration(c, r%model, r%st%q, pen, gmax, node)
        call watch_sink(r, pen, node)
        if (c%set%nact > 0) lmax = maxval(c%set%act(1:c%set%nact)%lambda)
        call output_history(r%out, r%st, r%bal, c%set%nact, contact_force_total(c), newton, &
                            max(pen, 0._dp), r%rep%neg_pivots, lmax, gmax, &
                            pair_normal_force(c), pair_active_count(c), norm2(c%impulse, dim=1), r%err, &
                            pair_tangential_force(c), c%friction_work, c%obstacle_work, &
                            merge(pair_stored_energy(c), c%correction_loss, c%opt%compliant))
      end associate
    else
      call output_history(r%out, r%st, r%bal, 0, 0._dp, newton, 0._dp, r%rep%neg_pivots, 0._dp, 0._dp, &
                          [real(dp) ::], [integer ::], [real(dp) ::], r%err)
    end if
  end subroutine history_row

  !> The state's history row (newton: its Newton iterations) and frame; .false. when either
  !> failed (failed says so)
  logical function row_and_frame(r, newton) result(ok)
    type(run_t), intent(inout) :: r
    integer, intent(in) :: newton
    call history_row(r, newton)
    ok = .not. failed(r, 'history')
    if (.not. ok) return
    call frame(r)
    ok = .not. failed(r, 'frame')
  end function row_and_frame

  subroutine frame(r)
    type(run_t), intent(inout) :: r
    real(dp), allocatable :: fc(:, :), sd(:, :)
    type(obstacle_t), allocatable :: obs(:)
    integer :: k
    if (.not. r%deck%output%vtu) return
    if (allocated(r%contact)) then
      allocate (fc(3, r%model%nnode), sd(1, r%model%nnode))
      call contact_nodal_fields(r%contact, r%model, fc)
      call contact_signed_distance(r%contact, r%model, r%st%q, sd(1, :))
      obs = r%contact%obstacle
      if (r%deck%run%analysis == 'static') then   ! (statics keep them where they are at t = 0)
        do k = 1, size(obs)
          obs(k)%velocity = 0
        end do
      end if
      call output_frame(r%out, r%model, r%st, [field('contact_force', fc), &
                                               field('signed_distance', sd)], r%err, obs)
    else
      call output_frame(r%out, r%model, r%st, [field_t ::], r%err)
    end if
  end subroutine frame

  !> r%err on any rank (collective: every rank stops with the same code): say what failed
  logical function failed(r, what)
    type(run_t), intent(inout) :: r
    character(len=*), intent(in) :: what
    call share_error(r%err)
    failed = allocated(r%err)
    if (failed) then
      if (is_root()) write (0, '(a,a,a,a)') 'error (', what, '): ', r%err%message
      r%code = exit_solver
      if (what == 'output' .or. what == 'setup' .or. what == 'restart') r%code = exit_input
      if (r%code == exit_solver) call mark_failed(r, r%err%message)
      call output_release(r%out)
    end if
  end function failed

  !> One line per frame: Newton iterations per step and the time left from the frame
  !> interval just done (contact makes later steps dearer than the first ones: from the
  !> start, a run that took 175 s had said 11 s left)
  subroutine progress(r)
    type(run_t), intent(inout) :: r
    real(dp) :: now, rate
    integer :: nc
    associate (st => r%st, last => r%last)
      now = wall_time()
      rate = (now - last%wall)/max(st%t - last%t, tiny(1._dp))
      nc = 0
      if (allocated(r%contact)) nc = r%contact%set%nact
      print '(a,i7,a,es11.4,a,es9.2,a,f6.2,a,i5,a,f8.1,a,f8.1,a)', 'step', st%step, '  t', st%t, &
        '  dt', r%nm%dt, '  newton/step', real(r%total_newton - last%newton)/max(st%step - last%step, 1), &
        '  contacts', nc, '  elapsed', now - r%t0, ' s  left', rate*max(r%deck%run%t_end - st%t, 0._dp), ' s'
      flush (output_unit)   ! (read as it goes from a file or a batch system's log, and kept if the run is killed)
      last = progress_t(now, st%t, st%step, r%total_newton)
    end associate
  end subroutine progress

  subroutine checkpoint(r)
    type(run_t), intent(inout) :: r
    type(error_t), allocatable :: e
    ! on every rank: a restart from here starts with new factors
    call r%ls%drop_factors()
    call output_flush(r%out, e)   ! the history up to this step, for a restart from here
    if (.not. allocated(e)) call save_checkpoint(r%dir//'/checkpoint.h5', r%model, r%st, r%level, &
                                                  r%bal%path_work, r%contact, e, r%dt_try, &
                                                  [r%dt_cap, r%cap_since, r%made_last])
    call share_error(e)
    if (allocated(e)) then
      if (is_root()) write (0, '(a,a)') 'error (checkpoint): ', e%message
      r%code = exit_solver
      call mark_failed(r, e%message)   ! (the checkpoint before this one is whole: written via .part)
      call output_release(r%out)
    else
      r%kept = r%dir//'/checkpoint.h5'
    end if
  end subroutine checkpoint

  !> An output could not be written (a full disk), the files are whole up to it: say so in
  !> stopped.txt if it can still be written (README: exit 3 leaves one), and how to restart
  subroutine mark_failed(r, why)
    type(run_t), intent(inout) :: r
    character(len=*), intent(in) :: why
    character(len=:), allocatable :: hint, text
    hint = restart_hint(r)
    text = 'this run stopped '//when(r)//': '//why
    if (hint /= '') text = text//new_line('a')//hint
    call output_mark_stopped(r%out, text)
    if (is_root() .and. hint /= '') write (0, '(a)') hint
  end subroutine mark_failed

  !> The command that goes on from the checkpoint r%kept ('' if none; without --out a restart
  !> goes to the deck's folder)
  function restart_hint(r) result(text)
    type(run_t), intent(in) :: r
    character(len=:), allocatable :: text
    text = ''
    if (r%kept == '') return
    text = 'restart: casca run '//r%deck%path//' --restart '//r%kept
    if (r%dir /= trim(r%deck%output%dir)) text = text//' --out '//r%dir
  end function restart_hint

  !> The solver cannot go on: keep the last good state (frame and checkpoint) and stop.
  subroutine give_up(r, why)
    type(run_t), intent(inout) :: r
    character(len=*), intent(in) :: why
    character(len=:), allocatable :: reason
    integer :: sig
    sig = stop_requested()
    if (sig > 0) then   ! (a stop asked for before or during the failure: what the user wants told)
      call stop_on_request(r, sig); return
    end if
    reason = why   ! (why may be r%err's message, which the frame and checkpoint below reset)
    if (is_root()) write (0, '(a)') 'error: the solver cannot go on '//when(r)//': '//reason
    ! (an earlier step that made energy is often the cause: a node come in edge-on)
    call warn_at_end(r)
    call watch_faces(r)   ! (the last good state)
    call keep_and_stop(r, reason)
    ! (a thin hoop bouncing off a dome under the trapezoidal rule: Newton stalled in free
    ! flight after the bounce; gamma 0.6 ran it through, docs/method.md)
    if (is_root() .and. squeezed(r)) then
      write (0, '(a)') 'hint: '//squeeze_note(r)
    else if (is_root() .and. sudden_static_friction() .and. &
             (index(reason, 'did not settle') > 0 .or. index(reason, 'did not converge') > 0)) then
      ! (a plate at rest on an incline: its edge nodes pass the static cone first and shed
      ! their load row after row within the step, docs/performance.md)
      write (0, '(a)') 'hint: static_friction is above friction with no friction_decay: a node '// &
        'past its static cone drops at once to the dynamic coefficient and sheds its load onto '// &
        'its neighbours, which may slip in turn within the step; friction_decay (&contact, '// &
        'e.g. 100 s/m) lets the drop follow the slip speed (README)'
    else if (is_root() .and. index(reason, 'singular Schur complement') > 0 .and. .not. r%ls%auto) then
      write (0, '(a)') 'hint: the Schur complement C K^-1 C^T fails where the stiffness K is '// &
        'near-singular in directions the contacts hold (a buckled shell); solver = ''saddle'' '// &
        '(&contact) factorises the whole saddle-point matrix, which is regular there'
    else if (is_root() .and. index(reason, 'did not come to rest') > 0) then
      write (0, '(a)') 'hint: near load factor '//rtoa(r%st%t)//' the structure buckles or snaps: '// &
        'past that point load control has no stable equilibrium near, and smaller load steps '// &
        'come no nearer one; analysis = ''dynamic'' follows where the structure goes (longer '// &
        'load steps may step past it onto the unstable path beyond, with a warning)'
    else if (is_root() .and. index(reason, 'static Newton did not converge') > 0 .and. &
             index(reason, 'no equilibrium: body') == 0) then
      write (0, '(a)') 'hint: more load_steps (&run, now '//itoa(r%deck%run%load_steps)//') start '// &
        'from smaller increments, and a larger max_step_cuts (now '//itoa(r%deck%run%max_step_cuts)// &
        ') lets a load step be halved more often'
    else if (is_root() .and. r%nm%gamma <= 0.5_dp .and. r%deck%run%analysis /= 'static') then
      write (0, '(a)') 'hint: '//r%nm%describe()//' keeps the shells'' fastest vibrations '// &
        'undamped, which can stall Newton; rho_inf = 0.8 (generalized-alpha) damps them, '// &
        'second order (or beta = 0.3025, gamma = 0.6; or the thesis'' beta = 1, gamma = 1.5)'
    end if
    r%code = exit_solver
  contains
    logical function sudden_static_friction()
      sudden_static_friction = .false.
      if (allocated(r%contact)) sudden_static_friction = &
        any(r%contact%mu_s > r%contact%mu_d .and. .not. r%contact%v_decay > 0)
    end function sudden_static_friction
  end subroutine give_up

  !> where a run that stops early is: its time, or in statics its load factor
  function when(r) result(text)
    type(run_t), intent(in) :: r
    character(len=:), allocatable :: text
    if (r%deck%run%analysis == 'static') then
      text = 'after load factor '//rtoa(r%st%t)//' of 1'
    else
      text = 'at t = '//rtoa(r%st%t)//' s of t_end = '//rtoa(r%deck%run%t_end)//' s'
    end if
  end function when

  !> A stop signal came (stop_request): the step under way was finished (or, in statics,
  !> abandoned: a load step can take minutes); keep the last step's state as a frame and
  !> checkpoint and stop with exit_signal, so that --restart goes on from here
  subroutine stop_on_request(r, sig)
    type(run_t), intent(inout) :: r
    integer, intent(in) :: sig
    if (is_root()) write (0, '(a)') 'casca: '//signal_name(sig)//' received; stopped '//when(r)
    call keep_and_stop(r, 'stopped by '//signal_name(sig))
    if (r%code == exit_ok) r%code = exit_signal
  end subroutine stop_on_request

  !> The run ends early: the state now as a frame and checkpoint.h5, stopped.txt saying when
  !> and why, the files closed. r%code is exit_solver if the state could not be written.
  subroutine keep_and_stop(r, reason)
    type(run_t), intent(inout) :: r
    character(len=*), intent(in) :: reason
    type(error_t), allocatable :: e
    character(len=:), allocatable :: where_kept
    if (allocated(r%contact)) r%contact%time = r%st%t   ! (a failed step left its end's)
    call frame(r)
    call checkpoint(r)
    call r%ls%finish()
    if (r%code == exit_solver) return   ! (checkpoint said why, and where a restart can start)
    where_kept = 'the last good state is in '//r%kept
    ! (a body that nothing holds has no equilibrium to go on to, from any state)
    if (index(reason, 'no equilibrium: body') == 0) where_kept = where_kept//' ('//restart_hint(r)//')'
    if (r%deck%output%vtu) where_kept = where_kept//' and in the last frame of '//r%dir//'/run.pvd'
    call output_mark_stopped(r%out, 'this run stopped '//when(r)//': '//reason//new_line('a')//where_kept)
    call output_close(r%out, e)
    if (is_root()) write (0, '(a)') where_kept
  end subroutine keep_and_stop

  !> Close the files, draw the plots, print the summary (and, for a dynamic run from t = 0,
  !> what it kept and the energy balance)
  subroutine finish(r)
    type(run_t), intent(inout) :: r
    type(error_t), allocatable :: e
    character(len=indicator_line_len), allocatable :: lines(:), warnings(:)
    character(len=:), allocatable :: from
    logical :: missing
    integer :: k
    call r%ls%finish()
    call output_close(r%out, e)
    call share_error(e)
    if (allocated(e)) then
      if (is_root()) write (0, '(a,a)') 'error (output): ', e%message
      r%code = exit_solver
      call mark_failed(r, e%message); return
    end if
    if (r%deck%output%plots .and. is_root()) then
      call make_plots(r%dir, e, missing, static=r%deck%run%analysis == 'static')
      if (allocated(e)) write (0, '(a,a)') 'warning: plots: ', e%message
      if (missing) write (0, '(a)') 'warning: gnuplot is not installed: '//r%dir// &
        '/plots.gp was written but not run'
    end if
    call warn_at_end(r)
    if (is_root() .and. squeezed(r)) write (0, '(a)') 'warning: '//squeeze_note(r)
    if (.not. is_root() .or. r%quiet) return
    associate (deck => r%deck, model => r%model)
      ! (the steps of this run: a restart's go on from the checkpoint's)
      from = ''
      if (r%restart_step >= 0) from = ' (from step '//itoa(r%restart_step)//' to '//itoa(r%st%step)//')'
      print '(a)', 'done: '//count_of(r%st%step - max(r%restart_step, 0), 'step', 'steps')//' in '// &
        seconds(wall_time() - r%t0)//' s'//from//'; results in '//r%dir
      print '(a)', timer_report(wall_time() - r%t0)
      if (deck%run%analysis /= 'static' .and. r%restart_step < 0) then
        print '(a)', balance_summary(r%bal0, r%bal, model%length, any(model%fixed) .or. &
                                     any(r%fext /= 0) .or. size(deck%obstacles) > 0 .or. &
                                     any(model%pressure /= 0) .or. any(model%moment /= 0))
        print '(a)', energy_balance(r%bal0, r%bal, balance_terms(deck, r%contact, corrections=.true.), &
                                    held=r%e_scale)
      end if
      ! the mesh indicator of the last state, per body (issue 18)
      call output_indicator_report(r%out, model, r%st, lines, warnings)
      print '(a)', (trim(lines(k)), k=1, size(lines))
      do k = 1, size(warnings)   ! (stderr, as the others)
        write (0, '(a)') trim(warnings(k))
      end do
    end associate
  end subroutine finish
  !> The run's energies and momenta now (accounting.f90); the total holds a compliant contact's
  !> energy too, as a spring's (the balance's remainder counts it as a term of its own)
  subroutine account_state(r, factor)
    type(run_t), intent(inout) :: r
    real(dp), intent(in), optional :: factor   !< statics: the load factor
    if (present(factor)) then
      call account(r%model, r%asm, r%st, r%fext*factor, r%q0, r%bal, factor=factor)
    else
      call account(r%model, r%asm, r%st, r%fext, r%q0, r%bal)
    end if
    if (allocated(r%contact)) r%bal%total = r%bal%total + sum(pair_stored_energy(r%contact))
  end subroutine account_state
end module casca_run
