!> What a run leaves in its output folder (rank 0 writes, the others pass):
!>   frame_NNNNN.vtu + run.pvd   ParaView frames with their times
!>   history.dat + history.h5     one row per step: energies, momenta, contacts, tracked nodes
!>   tracked.txt                  a label per tracked node (for the plots)
module casca_output
  use casca_kinds, only: dp
  use casca_error, only: error_t, fatal_error
  use casca_model, only: model_t, dof, element_dofs
  use casca_newmark, only: state_t
  use casca_accounting, only: balance_t
  use casca_shell_element, only: shell_von_mises
  use casca_vtu_writer, only: field_t, field, write_vtu, write_pvd
  use casca_hdf5_io, only: h5_table_t, h5_table_create, h5_table_append, h5_table_flush, &
                           h5_table_close, h5_table_open_append
  use casca_mpi, only: is_root
  implicit none
  private
  public :: output_t, output_open, output_history, output_frame, output_close

  type :: output_t
    character(len=:), allocatable :: dir
    integer :: hist = 0                 !< unit of history.dat (newunit: negative)
    logical :: hist_open = .false.
    type(h5_table_t) :: h5
    integer :: nframes = 0
    character(len=32), allocatable :: files(:)
    real(dp), allocatable :: times(:)
    integer, allocatable :: tracked(:)
    integer :: rows = 0
  end type output_t

contains

  !> Column names of the history (also the header of history.dat).
  function history_columns(ntrack) result(cols)
    integer, intent(in) :: ntrack
    character(len=16), allocatable :: cols(:)
    character(len=*), parameter :: suffix(6) = [character(len=3) :: '_x', '_y', '_z', '_vx', '_vy', '_vz']
    character(len=8) :: p
    integer :: k, c
    cols = [character(len=16) :: 't', 'step', 'kinetic', 'strain', 'work', 'total', 'px', 'py', &
            'pz', 'Lx', 'Ly', 'Lz', 'contacts', 'fcontact', 'newton', 'penetration', 'neg_pivots', &
            'lambda_max', 'gap_max']
    do k = 1, ntrack
      write (p, '(a,i0)') 'p', k
      do c = 1, 6
        cols = [cols, trim(p)//trim(suffix(c))]
      end do
    end do
  end function history_columns

  !> Create the folder and the files; with restart_step >= 0 keep what an earlier run wrote up
  !> to that step (and the frames up to restart_time) and append after it.
  subroutine output_open(out, dir, tracked, labels, restart_step, restart_time, err)
    type(output_t), intent(out) :: out
    character(len=*), intent(in) :: dir
    integer, intent(in) :: tracked(:)
    character(len=*), intent(in) :: labels(:)
    integer, intent(in) :: restart_step
    real(dp), intent(in) :: restart_time
    type(error_t), allocatable, intent(out) :: err
    character(len=16), allocatable :: cols(:)
    integer :: u, ios, k, stat
    character(len=256) :: msg

    out%dir = trim(dir)
    out%tracked = tracked
    allocate (out%files(0), out%times(0))
    if (.not. is_root()) return
    call execute_command_line('mkdir -p "'//out%dir//'"', exitstat=stat, cmdstat=ios)
    if (ios /= 0 .or. stat /= 0) then
      call fatal_error(err, 'cannot create the output folder '//out%dir); return
    end if
    cols = history_columns(size(tracked))
    open (newunit=u, file=out%dir//'/tracked.txt', status='replace', iostat=ios, iomsg=msg)
    if (ios /= 0) then
      call fatal_error(err, out%dir//'/tracked.txt: '//trim(msg)); return
    end if
    do k = 1, size(tracked)
      write (u, '(a)') trim(labels(k))
    end do
    close (u)
    if (restart_step < 0) then
      open (newunit=out%hist, file=out%dir//'/history.dat', status='replace', iostat=ios, &
            iomsg=msg)
      if (ios /= 0) then
        call fatal_error(err, out%dir//'/history.dat: '//trim(msg)); return
      end if
      out%hist_open = .true.
      write (out%hist, '(a,*(1x,a))') '#', (trim(cols(k)), k=1, size(cols))
      call h5_table_create(out%h5, out%dir//'/history.h5', cols, err)
    else
      call keep_history(restart_step, err)
      if (allocated(err)) return
      call h5_table_open_append(out%h5, out%dir//'/history.h5', size(cols), out%rows, err)
      if (allocated(err)) return
      call keep_frames(restart_time, err)
    end if
  contains
    !> rewrite history.dat with its header and the rows of steps <= last
    subroutine keep_history(last, e)
      integer, intent(in) :: last
      type(error_t), allocatable, intent(out) :: e
      character(len=:), allocatable :: line
      character(len=8192) :: buf
      character(len=8192), allocatable :: keep(:)
      real(dp) :: tt, ss
      integer :: uu, i
      open (newunit=uu, file=out%dir//'/history.dat', status='old', iostat=ios, iomsg=msg)
      if (ios /= 0) then
        call fatal_error(e, 'restart: '//out%dir//'/history.dat: '//trim(msg)); return
      end if
      allocate (keep(0))
      out%rows = 0
      do
        read (uu, '(a)', iostat=ios) buf
        if (ios /= 0) exit
        line = trim(buf)
        if (line(1:1) /= '#') then
          read (line, *, iostat=ios) tt, ss
          if (ios /= 0 .or. nint(ss) > last) exit
          out%rows = out%rows + 1
        end if
        keep = [keep, buf]
      end do
      close (uu)
      open (newunit=out%hist, file=out%dir//'/history.dat', status='replace')
      out%hist_open = .true.
      do i = 1, size(keep)
        write (out%hist, '(a)') trim(keep(i))
      end do
    end subroutine keep_history

    !> the frames of the earlier run.pvd with time <= tmax
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
        out%nframes = out%nframes + 1
        out%files = [out%files, buf(i2 + 6:i2 + 5 + index(buf(i2 + 6:), '"') - 1)]
        out%times = [out%times, tt]
      end do
      close (uu)
    end subroutine keep_frames
  end subroutine output_open

  !> One row: time, energies, momenta, contacts, Newton iterations, deepest penetration of a
  !> node without constraint, negative pivots of the last factorisation (the inertia of the
  !> saddle-point matrix: one per active constraint), the most tensile multiplier and the
  !> largest |gap| of the active constraints (the contact conditions at the accepted step),
  !> tracked nodes.
  subroutine output_history(out, st, bal, contacts, fcontact, newton, penetration, neg_pivots, &
                            lambda_max, gap_max, err)
    type(output_t), intent(inout) :: out
    type(state_t), intent(in) :: st
    type(balance_t), intent(in) :: bal
    integer, intent(in) :: contacts, newton, neg_pivots
    real(dp), intent(in) :: fcontact, penetration, lambda_max, gap_max
    type(error_t), allocatable, intent(out) :: err
    real(dp), allocatable :: row(:)
    integer :: k, n
    if (.not. is_root()) return
    row = [st%t, real(st%step, dp), bal%kinetic, bal%strain, bal%work, bal%total, bal%p, bal%l, &
           real(contacts, dp), fcontact, real(newton, dp), penetration, real(neg_pivots, dp), &
           lambda_max, gap_max]
    do k = 1, size(out%tracked)
      n = out%tracked(k)
      row = [row, st%q(dof(n, 1):dof(n, 3)), st%qd(dof(n, 1):dof(n, 3))]
    end do
    write (out%hist, '(es23.15e3,1x,i0,*(1x,es23.15e3))') row(1), st%step, row(3:)
    out%rows = out%rows + 1
    call h5_table_append(out%h5, row, err)
  end subroutine output_history

  !> A VTU frame of the state and its entry in run.pvd. extra: more point fields (contact).
  subroutine output_frame(out, model, st, extra, err)
    type(output_t), intent(inout) :: out
    type(model_t), intent(in) :: model
    type(state_t), intent(in) :: st
    type(field_t), intent(in) :: extra(:)
    type(error_t), allocatable, intent(out) :: err
    real(dp), allocatable :: x(:, :), u(:, :), v(:, :), g(:, :), a(:, :), body(:, :), vm(:, :)
    character(len=32) :: name
    integer :: n, e, b
    if (.not. is_root()) return
    allocate (x(3, model%nnode), u(3, model%nnode), v(3, model%nnode), g(3, model%nnode), &
              a(1, model%nnode), body(1, model%nelem), vm(1, model%nelem))
    do n = 1, model%nnode
      x(:, n) = st%q(dof(n, 1):dof(n, 3))
      u(:, n) = x(:, n) - model%x0(:, n)
      v(:, n) = st%qd(dof(n, 1):dof(n, 3))
      g(:, n) = st%q(dof(n, 4):dof(n, 6))
      a(1, n) = st%q(dof(n, 7))
    end do
    do e = 1, model%nelem
      b = model%elem_body(e)
      body(1, e) = b
      vm(1, e) = shell_von_mises(model%x0(:, model%conn(:, e)), model%v0(:, model%conn(:, e)), &
                                 model%body(b)%thickness, model%body(b)%lam, model%body(b)%mu, &
                                 reshape(st%q(element_dofs(model, e)), [7, 10]), 1._dp/3, 1._dp/3)
    end do
    write (name, '(a,i5.5,a)') 'frame_', out%nframes, '.vtu'
    ! geometry in the current configuration: ParaView shows the deformed shells directly
    call write_vtu(out%dir//'/'//trim(name), x, model%conn, &
                   [field('displacement', u), field('velocity', v), field('fibre', g), &
                    field('thickness_param', a), extra], &
                   [field('body', body), field('von_mises', vm)], err)
    if (allocated(err)) return
    out%nframes = out%nframes + 1
    out%files = [out%files, name]
    out%times = [out%times, st%t]
    call write_pvd(out%dir//'/run.pvd', out%files, out%times, err)
  end subroutine output_frame

  subroutine output_close(out, err)
    type(output_t), intent(inout) :: out
    type(error_t), allocatable, intent(out) :: err
    if (.not. is_root()) return
    if (out%hist_open) close (out%hist)
    out%hist_open = .false.
    call h5_table_flush(out%h5, err)
    if (allocated(err)) return
    call h5_table_close(out%h5, err)
  end subroutine output_close
end module casca_output
