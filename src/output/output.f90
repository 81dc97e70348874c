!> What a run leaves in its output folder (rank 0 writes, the others pass):
!>   frame_NNNNN.vtu + run.pvd   ParaView frames with their times
!>   obstacles_NNNNN.vtu          the rigid obstacles at frame NNNNN's time (a scene with
!>                                obstacles), part 1 of run.pvd beside the bodies' part 0
!>   history.dat + history.h5     one row per step: energies, momenta, contacts, tracked nodes,
!>                                energies per body, force and contacts per contact pair
!>   tracked.txt                  a label per tracked node (for the plots)
!> Each frame carries the mesh indicator per cell (casca_mesh_indicator); the last one computed
!> is kept for the run's end report (output_indicator_report).
module casca_output
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use, intrinsic :: iso_fortran_env, only: int64
  use casca_kinds, only: dp
  use casca_error, only: error_t, fatal_error
  use casca_model, only: model_t, dof, element_dofs, element_energy, thickness_stretch
  use casca_obstacle, only: obstacle_t
  use casca_obstacle_surface, only: obstacle_surfaces
  use casca_newmark, only: state_t
  use casca_accounting, only: balance_t
  use casca_shell_element, only: shell_stress, von_mises, shell_energy_force, ndof_elem
  use casca_shape_tri10, only: tri10_node_xi
  use casca_vtu_writer, only: field_t, field, write_vtu, write_pvd
  use casca_hdf5_io, only: h5_table_t, h5_table_create, h5_table_append, h5_table_flush, &
                           h5_table_close
  use casca_mpi, only: is_root
  use casca_strings, only: itoa, as_word
  use casca_files, only: make_dir, rename_file, delete_file, cut_to_last_line, file_kind, kind_missing, &
                         kind_regular
  use casca_checked_file, only: checked_file_t, cf_open, cf_write, cf_flush, cf_close, &
                                cf_discard, write_file_atomic
  use casca_output_lock, only: lock_folder, unlock_folder, locked_here
  use casca_plots, only: plot_files
  use casca_mesh_indicator, only: indicator_t, mesh_indicator, indicator_lines, indicator_warnings, &
                                  indicator_line_len
  implicit none
  private
  public :: output_t, output_open, output_history, output_frame, output_close, output_flush, &
            output_release, output_indicator_report, output_mark_stopped

  !> written into the output folder by a run that stopped before t_end (why, when, and the
  !> state to restart from), removed when a run opens the folder: the history and frames of
  !> such a run are whole, so only this says they end early
  character(len=*), parameter :: stopped_name = 'stopped.txt'

  type :: output_t
    character(len=:), allocatable :: dir
    type(checked_file_t) :: hist        !< history.dat
    logical :: hist_open = .false.
    type(h5_table_t) :: h5
    integer :: nframes = 0
    character(len=32), allocatable :: files(:)
    character(len=32), allocatable :: parts(:)   !< each frame's obstacles' file ('' none)
    real(dp), allocatable :: times(:)
    integer, allocatable :: tracked(:)
    integer :: nbody = 0, npairs = 0    !< per-body and per-pair columns
    logical :: friction = .false.       !< the pairs' tangential forces and the friction work too
    logical :: moving = .false.         !< the work of moving obstacles too
    integer :: rows = 0
    logical :: locked = .false.         !< this run holds the folder's lock
    type(indicator_t) :: ind            !< the mesh indicator of the last frame ...
    integer :: ind_step = -1            !< ... and its step (-1: none yet)
  end type output_t

  integer, parameter :: max_line = 65536   !< longest history.dat line read back at a restart
  integer, parameter :: col_len = 160      !< longest column name: prefix and two 64-character names

contains

  !> Column names of the history (also the header of history.dat): the fixed ones, the
  !> tracked nodes', then per body (kinetic_B, strain_B) and per contact pair (fcontact_P,
  !> contacts_P, impulse_P: the magnitude of the impulse on the impactor so far); the per-body and per-pair columns come last, so that the older ones keep
  !> their positions. Names are single words of letters, digits and '_' (anything else in a
  !> body's name becomes '_'), which numpy's genfromtxt(names=True) keeps as they are.
  !> With friction, then ftangent_P per pair and friction_work (dissipated by sliding); with
  !> moving obstacles, obstacle_work (done on the bodies); then, each after all the above so
  !> that they keep their positions, with friction friction_work_P per pair, and per pair
  !> with a compliant contact contact_energy_P (what its compliance holds), with a hard one
  !> contact_loss_P (the kinetic energy its velocity corrections took out).
  function history_columns(ntrack, bodies, pairs, friction, moving, compliant) result(cols)
    integer, intent(in) :: ntrack
    character(len=*), intent(in) :: bodies(:), pairs(:)
    logical, intent(in) :: friction, moving, compliant
    character(len=col_len), allocatable :: cols(:)
    character(len=*), parameter :: suffix(6) = [character(len=3) :: '_x', '_y', '_z', '_vx', '_vy', '_vz']
    character(len=8) :: p
    integer :: k, c
    cols = [character(len=col_len) :: 't', 'step', 'kinetic', 'strain', 'work', 'total', 'px', 'py', &
            'pz', 'Lx', 'Ly', 'Lz', 'contacts', 'fcontact', 'newton', 'penetration', 'neg_pivots', &
            'lambda_max', 'gap_max']
    do k = 1, ntrack
      write (p, '(a,i0)') 'p', k
      do c = 1, 6
        cols = [character(len=col_len) :: cols, trim(p)//trim(suffix(c))]
      end do
    end do
    cols = [cols, (word('kinetic_'//trim(bodies(k))), k=1, size(bodies)), &
            (word('strain_'//trim(bodies(k))), k=1, size(bodies)), &
            (word('fcontact_'//trim(pairs(k))), k=1, size(pairs)), &
            (word('contacts_'//trim(pairs(k))), k=1, size(pairs)), &
            (word('impulse_'//trim(pairs(k))), k=1, size(pairs))]
    if (friction) cols = [cols, (word('ftangent_'//trim(pairs(k))), k=1, size(pairs)), &
                          word('friction_work')]
    if (moving) cols = [cols, word('obstacle_work')]
    if (friction) cols = [cols, (word('friction_work_'//trim(pairs(k))), k=1, size(pairs))]
    if (compliant) then
      cols = [cols, (word('contact_energy_'//trim(pairs(k))), k=1, size(pairs))]
    else
      cols = [cols, (word('contact_loss_'//trim(pairs(k))), k=1, size(pairs))]
    end if
  contains
    pure function word(name) result(w)
      character(len=*), intent(in) :: name
      character(len=col_len) :: w
      w = as_word(name)
    end function word
  end function history_columns

  !> Create the folder, lock it (casca_output_lock) and make the files; with restart_step >= 0
  !> keep what an earlier run wrote up to that step (and the frames up to restart_time) and
  !> append after it. bodies: the bodies' names; pairs: a label per contact pair.
  subroutine output_open(out, dir, tracked, labels, bodies, pairs, friction, moving, compliant, &
                         restart_step, restart_time, err, restart_dir)
    type(output_t), intent(out) :: out
    logical, intent(in) :: friction, moving, compliant
    character(len=*), intent(in) :: dir
    integer, intent(in) :: tracked(:)
    character(len=*), intent(in) :: labels(:), bodies(:), pairs(:)
    integer, intent(in) :: restart_step
    real(dp), intent(in) :: restart_time
    type(error_t), allocatable, intent(out) :: err
    character(len=*), intent(in), optional :: restart_dir   !< the checkpoint's folder
    character(len=col_len), allocatable :: cols(:)
    character(len=:), allocatable :: note, earlier
    integer :: ios, k
    character(len=256) :: msg
    logical :: own

    out%dir = trim(dir)
    out%tracked = tracked
    out%nbody = size(bodies); out%npairs = size(pairs); out%friction = friction; out%moving = moving
    allocate (out%files(0), out%parts(0), out%times(0))
    if (.not. is_root()) return
    if (.not. make_dir(out%dir)) then
      call fatal_error(err, 'cannot create the output folder '//out%dir// &
                       ' (the deck''s &output: dir, or --out; is its parent writable?)'); return
    end if
    call lock_folder(out%dir, note, err)
    if (allocated(err)) return
    out%locked = .true.
    if (note /= '') write (0, '(a)') 'warning: '//note
    cols = history_columns(size(tracked), bodies, pairs, friction, moving, compliant)
    ! a restart carries on the checkpoint folder's history, and into another folder leaves
    ! its frames there: what the other folder held is not taken (another run's rows were kept
    ! as this run's) unless the checkpoint's folder has no history (a checkpoint copied away
    ! from its results); with none at all, the history starts anew
    earlier = out%dir//'/history.dat'
    own = .true.
    if (present(restart_dir)) then
      own = locked_here(restart_dir) .or. file_kind(restart_dir//'/history.dat') == kind_missing
      if (.not. own) earlier = restart_dir//'/history.dat'
    end if
    if (restart_step >= 0 .and. file_kind(earlier) == kind_missing .and. &
        file_kind(out%dir//'/run.pvd') /= kind_missing) then   ! (its frames would be written over)
      call fatal_error(err, 'restart: '//earlier//' is missing, though '//out%dir//' holds an '// &
                       'earlier run''s frames (run.pvd): the history up to the checkpoint would be '// &
                       'lost and those frames written over; put history.dat back, or restart into a '// &
                       'new folder (--out)')
      return
    end if
    ! (from here the folder is this run's: a refused restart leaves it as it was)
    call delete_file(out%dir//'/'//stopped_name)   ! (an earlier run's)
    ! an earlier run's plots, unless this run carries on the history they were drawn from (a
    ! stopped or killed run left them beside its own history, as its own)
    if (restart_step < 0 .or. .not. own .or. file_kind(earlier) == kind_missing) then
      do k = 1, size(plot_files)
        call delete_file(out%dir//'/'//trim(plot_files(k)))
      end do
    end if
    call write_file_atomic(out%dir//'/tracked.txt', join(labels, '', new_line('a')), err)
    if (allocated(err)) return
    if (restart_step < 0 .or. file_kind(earlier) == kind_missing) then
      call cf_open(out%hist, out%dir//'/history.dat', 'w', err)
      if (allocated(err)) return
      out%hist_open = .true.
      call cf_write(out%hist, '#'//join(cols, ' ', '')//new_line('a'), err)
      ! the header on disk now: a frame that fills the disk before the first flush would
      ! otherwise leave history.dat without it
      if (.not. allocated(err)) call cf_flush(out%hist, err)
      if (allocated(err)) return
      call h5_table_create(out%h5, out%dir//'/history.h5', cols, err, in_memory=.true.)
    else
      call keep_history(out, cols, restart_step, earlier, err)
      if (allocated(err)) return
      if (own) call keep_frames(restart_time, err)
      if (allocated(err)) return
    end if
    call drop_frames()
  contains
    !> An earlier run's frames and obstacles past those this run keeps, and its run.pvd when
    !> it keeps none: left there, ParaView's frame_* series would mix the two runs (numbered
    !> on from 0)
    subroutine drop_frames()
      integer :: k
      if (out%nframes == 0) call delete_file(out%dir//'/run.pvd')
      k = out%nframes
      do while (file_kind(out%dir//'/'//frame_name(k)) /= kind_missing .or. &
                file_kind(out%dir//'/'//obstacles_name(k)) /= kind_missing)
        call delete_file(out%dir//'/'//frame_name(k))   ! (a missing one is left alone)
        call delete_file(out%dir//'/'//obstacles_name(k))
        k = k + 1
      end do
    end subroutine drop_frames

    !> the frames of the earlier run.pvd with time <= tmax, with their obstacles (part 1)
    subroutine keep_frames(tmax, e)
      real(dp), intent(in) :: tmax
      type(error_t), allocatable, intent(out) :: e
      character(len=1024) :: buf
      integer :: uu, i1, i2
      real(dp) :: tt
      open (newunit=uu, file=out%dir//'/run.pvd', status='old', iostat=ios, iomsg=msg)
      if (ios /= 0) return   ! no frames were written (vtu = .false.)
      do
        read (uu, '(a)', iostat=ios) buf
        if (ios /= 0) exit
        i1 = index(buf, 'timestep="'); i2 = index(buf, 'file="')
        if (i1 == 0 .or. i2 == 0) cycle
        read (buf(i1 + 10:i1 + 8 + index(buf(i1 + 10:), '"')), *, iostat=ios) tt
        if (ios /= 0) then
          call fatal_error(e, 'restart: '//out%dir//'/run.pvd: unreadable timestep'); return
        end if
        if (tt > tmax*(1 + 1e-12_dp) + tiny(1._dp)) exit
        if (index(buf, 'part="1"') > 0) then   ! (after its frame's line, at its time)
          if (out%nframes > 0) out%parts(out%nframes) = buf(i2 + 6:i2 + 5 + index(buf(i2 + 6:), '"') - 1)
          cycle
        end if
        out%nframes = out%nframes + 1
        out%files = [character(len=32) :: out%files, buf(i2 + 6:i2 + 5 + index(buf(i2 + 6:), '"') - 1)]
        out%parts = [character(len=32) :: out%parts, '']
        out%times = [out%times, tt]
      end do
      close (uu)
    end subroutine keep_frames
  end subroutine output_open

  !> Restart: cut history.dat (from earlier: this folder's, or the checkpoint folder's) back to
  !> the rows of steps <= last (rows after the checkpoint, or a line cut short by a crash, go),
  !> which must end at step last, and make history.h5 anew
  !> from them: the .dat is flushed at every checkpoint, while an HDF5 file killed between two
  !> flushes may be unreadable. Nothing is changed unless the history reaches step last.
  subroutine keep_history(out, cols, last, earlier, err)
    type(output_t), intent(inout) :: out
    character(len=*), intent(in) :: cols(:), earlier
    integer, intent(in) :: last
    type(error_t), allocatable, intent(out) :: err
    character(len=:), allocatable :: path
    character(len=max_line) :: buf
    character(len=256) :: msg
    real(dp) :: row(size(cols))
    integer :: u, ios
    path = out%dir//'/history.dat'
    call cut_history(earlier, path, size(cols), last, err)
    if (allocated(err)) return
    call h5_table_create(out%h5, out%dir//'/history.h5', cols, err, in_memory=.true.)
    if (allocated(err)) return
    open (newunit=u, file=path, status='old', action='read', iostat=ios, iomsg=msg)
    do while (ios == 0 .and. .not. allocated(err))
      read (u, '(a)', iostat=ios) buf
      if (ios /= 0 .or. buf(1:1) == '#') cycle
      read (buf, *, iostat=ios) row
      out%rows = out%rows + 1
      call h5_table_append(out%h5, row, err)
    end do
    close (u)
    if (.not. allocated(err)) call h5_table_flush(out%h5, err)
    if (allocated(err)) return
    call cf_open(out%hist, path, 'a', err)
    out%hist_open = .not. allocated(err)
  end subroutine keep_history

  !> Replace the history file path by the header and rows (of ncol numbers) up to step last of
  !> the history earlier (path itself, or another folder's), written to path.part and renamed
  !> when complete; an error if the rows end before last.
  subroutine cut_history(earlier, path, ncol, last, err)
    character(len=*), intent(in) :: earlier, path
    integer, intent(in) :: ncol, last
    type(error_t), allocatable, intent(out) :: err
    type(checked_file_t) :: part
    character(len=max_line) :: buf
    character(len=256) :: msg
    real(dp) :: row(ncol)
    integer :: u, ios, step
    open (newunit=u, file=earlier, status='old', action='read', iostat=ios, iomsg=msg)
    if (ios /= 0) then
      call fatal_error(err, 'restart: '//earlier//': '//trim(msg)); return
    end if
    call cf_open(part, path//'.part', 'w', err)
    step = -1
    do while (.not. allocated(err))
      read (u, '(a)', iostat=ios) buf
      if (ios /= 0) exit
      if (buf(1:1) /= '#') then
        read (buf, *, iostat=ios) row
        if (ios /= 0 .or. nint(row(2)) > last) exit
        step = nint(row(2))
      end if
      call cf_write(part, trim(buf)//new_line('a'), err)
    end do
    close (u)
    if (.not. allocated(err)) call cf_close(part, err)
    ! (statics have no row for the unloaded state: one stopped in its first load step has none)
    if (.not. allocated(err) .and. step /= last .and. .not. (last == 0 .and. step == -1)) &
      call fatal_error(err, 'restart: '//earlier//' ends at step '//itoa(step)// &
                       ', before the checkpoint''s step '//itoa(last)//' (another run''s history?)')
    if (allocated(err)) then
      call cf_discard(part); return
    end if
    if (.not. rename_file(path//'.part', path)) &
      call fatal_error(err, 'restart: cannot rename '//path//'.part to '//path)
  end subroutine cut_history

  !> The words, trimmed, each between before and after, as one text
  pure function join(words, before, after) result(text)
    character(len=*), intent(in) :: words(:), before, after
    character(len=:), allocatable :: text
    integer :: k
    text = ''
    do k = 1, size(words)
      text = text//before//trim(words(k))//after
    end do
  end function join

  !> One row: time, energies, momenta, contacts, Newton iterations, deepest penetration of a
  !> node without constraint, negative pivots of the last factorisation (the inertia of the
  !> saddle-point matrix: one per active constraint), the most tensile multiplier and the
  !> largest |gap| of the active constraints (the contact conditions at the accepted step),
  !> tracked nodes, kinetic and strain energy per body (bal), normal force and active
  !> constraints per contact pair (pair_force, pair_count: as many as output_open's pairs).
  subroutine output_history(out, st, bal, contacts, fcontact, newton, penetration, neg_pivots, &
                            lambda_max, gap_max, pair_force, pair_count, pair_impulse, err, pair_tangent, &
                            pair_friction_work, obstacle_work, pair_energy)
    type(output_t), intent(inout) :: out
    type(state_t), intent(in) :: st
    type(balance_t), intent(in) :: bal
    integer, intent(in) :: contacts, newton, neg_pivots
    real(dp), intent(in) :: fcontact, penetration, lambda_max, gap_max
    real(dp), intent(in) :: pair_force(:), pair_impulse(:)
    integer, intent(in) :: pair_count(:)
    type(error_t), allocatable, intent(out) :: err
    !> per pair: the friction force's magnitude, the work sliding dissipated, the compliance's
    !> energy (hard contact: the velocity corrections' loss)
    real(dp), intent(in), optional :: pair_tangent(:), pair_friction_work(:), obstacle_work, pair_energy(:)
    real(dp), allocatable :: row(:)
    character(len=max_line) :: line
    integer :: k, n
    if (.not. is_root()) return
    row = [st%t, real(st%step, dp), bal%kinetic, bal%strain, bal%work, bal%total, bal%p, bal%l, &
           real(contacts, dp), fcontact, real(newton, dp), penetration, real(neg_pivots, dp), &
           lambda_max, gap_max]
    do k = 1, size(out%tracked)
      n = out%tracked(k)
      row = [row, st%q(dof(n, 1):dof(n, 3)), st%qd(dof(n, 1):dof(n, 3))]
    end do
    if (size(bal%body_kinetic) /= out%nbody .or. size(pair_force) /= out%npairs .or. &
        size(pair_count) /= out%npairs .or. size(pair_impulse) /= out%npairs) then
      call fatal_error(err, 'output_history: '//itoa(size(bal%body_kinetic))//' bodies and '// &
                       itoa(size(pair_force))//' pairs, the history has '//itoa(out%nbody)// &
                       ' and '//itoa(out%npairs))
      return
    end if
    row = [row, bal%body_kinetic, bal%body_strain, pair_force, real(pair_count, dp), pair_impulse]
    if (out%friction) row = [row, pair_tangent, sum(pair_friction_work)]
    if (out%moving) row = [row, obstacle_work]
    if (out%friction) row = [row, pair_friction_work]
    if (out%npairs > 0) row = [row, pair_energy]
    write (line, '(es23.15e3,1x,i0,*(1x,es23.15e3))') row(1), st%step, row(3:)
    call cf_write(out%hist, trim(line)//new_line('a'), err)
    ! (each row to the system whole: a killed run's history.dat ends with a whole row, and a
    ! running one can be plotted)
    if (.not. allocated(err)) call cf_flush(out%hist, err)
    if (allocated(err)) return
    out%rows = out%rows + 1
    call h5_table_append(out%h5, row, err)
  end subroutine output_history

  !> Push the history rows written so far to both files (at a checkpoint: a restart from it
  !> finds every row up to its step).
  subroutine output_flush(out, err)
    type(output_t), intent(inout) :: out
    type(error_t), allocatable, intent(out) :: err
    if (.not. is_root() .or. .not. out%hist_open) return
    call cf_flush(out%hist, err)
    if (.not. allocated(err)) call h5_table_flush(out%h5, err)
  end subroutine output_flush

  !> The file of frame k (from 0)
  pure function frame_name(k) result(name)
    integer, intent(in) :: k
    character(len=15) :: name
    write (name, '(a,i5.5,a)') 'frame_', k, '.vtu'
  end function frame_name

  !> The file of frame k's obstacles
  pure function obstacles_name(k) result(name)
    integer, intent(in) :: k
    character(len=19) :: name
    write (name, '(a,i5.5,a)') 'obstacles_', k, '.vtu'
  end function obstacles_name

  !> A VTU frame of the state and its entry in run.pvd. extra: more point fields (contact).
  !> obstacles: drawn where they are at the state's time, in a file of their own listed beside
  !> the frame (part 1).
  subroutine output_frame(out, model, st, extra, err, obstacles)
    type(output_t), intent(inout) :: out
    type(model_t), intent(in) :: model
    type(state_t), intent(in) :: st
    type(field_t), intent(in) :: extra(:)
    type(error_t), allocatable, intent(out) :: err
    type(obstacle_t), intent(in), optional :: obstacles(:)
    real(dp), allocatable :: x(:, :), u(:, :), v(:, :), g(:, :), a(:, :), body(:, :), thick(:, :)
    type(field_t), allocatable :: cell_stress(:), point_stress(:)
    character(len=32) :: name, part
    integer :: n
    if (.not. is_root()) return
    if (size(out%times) > 0) then   ! (a run stopped just after a frame keeps that one)
      if (out%times(size(out%times)) == st%t) return
    end if
    if (.not. (all(ieee_is_finite(st%q)) .and. all(ieee_is_finite(st%qd)))) then
      call fatal_error(err, 'the state at step '//itoa(st%step)//' is not finite; no frame written')
      return
    end if
    allocate (x(3, model%nnode), u(3, model%nnode), v(3, model%nnode), g(3, model%nnode), &
              a(1, model%nnode), thick(1, model%nnode))
    do n = 1, model%nnode
      x(:, n) = st%q(dof(n, 1):dof(n, 3))
      u(:, n) = x(:, n) - model%x0(:, n)
      v(:, n) = st%qd(dof(n, 1):dof(n, 3))
      g(:, n) = st%q(dof(n, 4):dof(n, 6))
      a(1, n) = st%q(dof(n, 7))
      thick(1, n) = model%body(model%node_body(n))%thickness*thickness_stretch(st%q, n)
    end do
    body = reshape(real(model%elem_body, dp), [1, model%nelem])
    call stress_fields(model, st%q, cell_stress, point_stress)
    call mesh_indicator(model, st%q, out%ind)
    out%ind_step = st%step
    name = frame_name(out%nframes)
    ! geometry in the current configuration: ParaView shows the deformed shells directly
    call write_vtu(out%dir//'/'//trim(name), x, model%conn, &
                   [field('displacement', u), field('velocity', v), field('fibre', g), &
                    field('thickness_param', a), field('thickness', thick), extra, point_stress], &
                   [field('body', body), field('strain_energy', cell_energy(model, st%q)), &
                    cell_stress, field('mesh_indicator', reshape(out%ind%rel, [1, model%nelem]), &
                                       single=.true.)], err)
    if (allocated(err)) return
    part = ''
    if (present(obstacles)) then
      if (size(obstacles) > 0) then
        part = obstacles_name(out%nframes)
        call write_obstacles(out%dir//'/'//trim(part), obstacles, st%t, x, err)
        if (allocated(err)) return
      end if
    end if
    out%nframes = out%nframes + 1
    out%files = [character(len=32) :: out%files, name]
    out%parts = [character(len=32) :: out%parts, part]
    out%times = [out%times, st%t]
    call write_pvd(out%dir//'/run.pvd', out%files, out%times, err, out%parts)
  end subroutine output_frame

  !> The obstacles at time t, drawn about the bodies' points x (casca_obstacle_surface), to
  !> path: per cell the obstacle's number (in the deck's order; the field data name them),
  !> per point its velocity
  subroutine write_obstacles(path, obstacles, t, x, err)
    character(len=*), intent(in) :: path
    type(obstacle_t), intent(in) :: obstacles(:)
    real(dp), intent(in) :: t, x(:, :)
    type(error_t), allocatable, intent(out) :: err
    real(dp), allocatable :: p(:, :), v(:, :)
    integer, allocatable :: tri(:, :), which(:)
    integer :: k
    call obstacle_surfaces(obstacles, t, x, p, tri, which)
    allocate (v(3, size(p, 2)))
    do k = 1, size(tri, 2)
      v(:, tri(:, k)) = spread(obstacles(which(k))%velocity, 2, 3)
    end do
    call write_vtu(path, p, tri, [field('velocity', v)], &
                   [field('obstacle', reshape(real(which, dp), [1, size(which)]))], err, &
                   labels=[(obstacles(k)%name, k=1, size(obstacles))])
  end subroutine write_obstacles

  !> The end report's lines of the mesh indicator (one per body) and its warnings for the
  !> state st: the last frame's when it was written at st's step, else computed now (vtu =
  !> .false., a restart without frames), so a run computes it at its frames and at most once
  !> more. Rank 0.
  subroutine output_indicator_report(out, model, st, lines, warnings)
    type(output_t), intent(inout) :: out
    type(model_t), intent(in) :: model
    type(state_t), intent(in) :: st
    character(len=indicator_line_len), allocatable, intent(out) :: lines(:), warnings(:)
    if (out%ind_step /= st%step .or. .not. allocated(out%ind%rel)) then
      call mesh_indicator(model, st%q, out%ind)
      out%ind_step = st%step
    end if
    lines = indicator_lines(model, out%ind)
    warnings = indicator_warnings(model, out%ind)
  end subroutine output_indicator_report

  !> The stress fields of a frame. Per cell, at the centroid: von_mises (mid-surface),
  !> von_mises_top, von_mises_bottom and the Cauchy stress tensors stress_top, stress_mid,
  !> stress_bottom (global axes, 6 components xx yy zz xy yz xz: ParaView's symmetric tensor,
  !> whose components it names so).
  !> Per point: the same tensors at the node, averaged over the elements around it. The
  !> tensors are written as Float32: they are most of a frame's bytes, and viewing needs no
  !> more than 7 digits.
  subroutine stress_fields(model, q, cells, points)
    type(model_t), intent(in) :: model
    real(dp), intent(in) :: q(:)
    type(field_t), allocatable, intent(out) :: cells(:), points(:)
    !> xi3 of the surfaces: top is the side the initial fibre points to
    real(dp), parameter :: xi3(3) = [1._dp, 0._dp, -1._dp]
    character(len=*), parameter :: surface(3) = [character(len=6) :: 'top', 'mid', 'bottom']
    real(dp), allocatable :: cell(:, :, :), node(:, :, :), vm(:, :, :), share(:)
    real(dp) :: sig(3, 3), qe(7, 10), x0(3, 10), v0(3, 10), h, lam, mu
    integer :: e, b, k, l, nodes(10)

    allocate (cell(6, model%nelem, 3), vm(1, model%nelem, 3), node(6, model%nnode, 3), &
              share(model%nnode))
    node = 0; share = 0
    do e = 1, model%nelem
      b = model%elem_body(e); h = model%body(b)%thickness
      lam = model%body(b)%lam; mu = model%body(b)%mu
      nodes = model%conn(:, e)
      x0 = model%x0(:, nodes); v0 = model%v0(:, nodes)
      qe = reshape(q(element_dofs(model, e)), [7, 10])
      do k = 1, 3
        sig = shell_stress(x0, v0, h, lam, mu, qe, 1._dp/3, 1._dp/3, xi3(k), model%linear)
        cell(:, e, k) = symmetric_components(sig)
        vm(1, e, k) = von_mises(sig)
        do l = 1, 10
          sig = shell_stress(x0, v0, h, lam, mu, qe, tri10_node_xi(1, l), tri10_node_xi(2, l), xi3(k), &
                             model%linear)
          node(:, nodes(l), k) = node(:, nodes(l), k) + symmetric_components(sig)
        end do
      end do
      share(nodes) = share(nodes) + 1
    end do
    do k = 1, 3
      node(:, :, k) = node(:, :, k)/spread(max(share, 1._dp), 1, 6)
    end do
    cells = [field('von_mises', vm(:, :, 2)), field('von_mises_top', vm(:, :, 1)), &
             field('von_mises_bottom', vm(:, :, 3)), &
             (field('stress_'//trim(surface(k)), cell(:, :, k), single=.true.), k=1, 3)]
    points = [(field('stress_'//trim(surface(k)), node(:, :, k), single=.true.), k=1, 3)]
  end subroutine stress_fields

  !> Each element's strain energy [J] (per cell: where a body stores its energy; they sum
  !> to the history's strain_B)
  function cell_energy(model, q) result(w)
    type(model_t), intent(in) :: model
    real(dp), intent(in) :: q(:)
    real(dp) :: w(1, model%nelem)
    integer :: e
    do e = 1, model%nelem
      w(1, e) = element_energy(model, q, e)
    end do
  end function cell_energy

  !> The 6 components of a symmetric tensor in ParaView's order: xx, yy, zz, xy, yz, xz.
  pure function symmetric_components(t) result(c)
    real(dp), intent(in) :: t(3, 3)
    real(dp) :: c(6)
    c = [t(1, 1), t(2, 2), t(3, 3), t(1, 2), t(2, 3), t(1, 3)]
  end function symmetric_components

  !> Close the files (every close checked: a full disk shows here last) and free the folder.
  subroutine output_close(out, err)
    type(output_t), intent(inout) :: out
    type(error_t), allocatable, intent(out) :: err
    if (.not. is_root()) return
    if (out%hist_open) call cf_close(out%hist, err)
    if (allocated(err)) call whole_lines(out%dir//'/history.dat')
    out%hist_open = .false.
    if (.not. allocated(err)) call h5_table_flush(out%h5, err)
    if (.not. allocated(err)) call h5_table_close(out%h5, err)
    call output_release(out)
  end subroutine output_close

  !> The run stopped early: say so in the folder (stopped_name), with the text given
  subroutine output_mark_stopped(out, text)
    type(output_t), intent(in) :: out
    character(len=*), intent(in) :: text
    type(error_t), allocatable :: e
    if (.not. is_root()) return
    call write_file_atomic(out%dir//'/'//stopped_name, text//new_line('a'), e)
    if (allocated(e)) write (0, '(a)') 'error (output): '//e%message
  end subroutine output_mark_stopped

  !> After an error: close what is open, quietly (the error is reported already), and free
  !> the folder.
  subroutine output_release(out)
    type(output_t), intent(inout) :: out
    type(error_t), allocatable :: e
    if (.not. is_root()) return
    if (out%hist_open) then
      call cf_close(out%hist, e)
      call whole_lines(out%dir//'/history.dat')
    end if
    out%hist_open = .false.
    call h5_table_close(out%h5, e)
    if (out%locked) call unlock_folder(out%dir)
    out%locked = .false.
  end subroutine output_release

  !> After a failed write: the history file cut to its last whole line, or gone if it has
  !> none (complete under its name or not there).
  subroutine whole_lines(path)
    character(len=*), intent(in) :: path
    integer(int64) :: bytes
    call cut_to_last_line(path)
    if (file_kind(path, bytes) == kind_regular) then
      if (bytes == 0) call delete_file(path)
    end if
  end subroutine whole_lines
end module casca_output
