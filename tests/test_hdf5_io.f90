!> Tests of casca_hdf5_io (src/output/hdf5_io.f90): history table and checkpoints.
!>
!> Run in a scratch working directory; it leaves there, for tests/test_hdf5_io.py:
!>   hdf5_io_table.h5    5 columns, 1000 rows: row i (1-based), column j = i*10 + j + 1/3
!>   hdf5_io_restart.h5  the same 1000 rows, reopened with nkeep = 600, then rows
!>                       i = 601..610 with value -(i*10 + j) - 1/3: 610 rows in all
!> Column names: time, energy_kin, energy_pot, u_tip, n_contact.
!> The tables are read back here through the HDF5 API directly (not through the module).
program test_hdf5_io
  use, intrinsic :: iso_fortran_env, only: int64
  use hdf5, only: hid_t, hsize_t, size_t, h5fopen_f, h5fclose_f, h5dopen_f, &
                  h5dclose_f, h5dget_space_f, h5dread_f, h5sclose_f, &
                  h5sget_simple_extent_ndims_f, h5sget_simple_extent_dims_f, h5aopen_f, &
                  h5aclose_f, h5aget_type_f, h5aget_space_f, h5aread_f, h5tget_size_f, &
                  h5tget_strpad_f, h5tclose_f, H5F_ACC_RDONLY_F, H5T_NATIVE_DOUBLE, &
                  H5T_STR_NULLPAD_F, h5fget_obj_count_f, H5F_OBJ_ALL_F
  use casca_kinds, only: dp
  use casca_error, only: error_t
  use casca_mpi, only: mpi_start, mpi_stop, wall_time
  use casca_check, only: check_le, check_true, check_summary
  use casca_hdf5_io, only: h5_table_t, h5_table_create, h5_table_append, h5_table_flush, &
                           h5_table_close, h5_table_open_append, h5_table_nrow, &
                           write_checkpoint, read_checkpoint
  implicit none

  integer, parameter :: ncol = 5, nrows = 1000, nkeep = 600, nmore = 10
  character(len=*), parameter :: table_file = 'hdf5_io_table.h5'
  character(len=*), parameter :: restart_file = 'hdf5_io_restart.h5'
  character(len=*), parameter :: ckpt_file = 'hdf5_io_ckpt.h5'
  character(len=*), parameter :: text_file = 'hdf5_io_not_h5.txt'
  character(len=*), parameter :: missing_file = 'hdf5_io_no_such_file.h5'
  character(len=16), parameter :: columns(ncol) = [character(len=16) :: 'time', &
                                     'energy_kin', 'energy_pot', 'u_tip', 'n_contact']

  call mpi_start()
  call test_table()
  call test_checkpoint()
  call test_errors()
  call test_nothing_left_open()
  call check_summary()
  call mpi_stop()

contains

  !> Row i, column j of the first run (positive) and of the restarted run (negative).
  pure real(dp) function val(i, j)
    integer, intent(in) :: i, j
    val = real(i*10 + j, dp) + 1.0_dp/3.0_dp
  end function val

  subroutine test_table()
    type(h5_table_t) :: tab, tab2
    type(error_t), allocatable :: err
    real(dp), allocatable :: a(:, :)
    character(len=64), allocatable :: names(:)
    real(dp) :: row(ncol), t0, elapsed
    integer :: i, j
    logical :: ok, nullpad

    ! Two identical tables of 1000 rows; the second is then reopened for a restart.
    t0 = wall_time()
    call h5_table_create(tab, table_file, columns, err)
    call ok_or_report('create '//table_file, err)
    call h5_table_create(tab2, restart_file, columns, err)
    call ok_or_report('create '//restart_file, err)
    ok = .true.
    do i = 1, nrows
      row = [(val(i, j), j=1, ncol)]
      call h5_table_append(tab, row, err)
      if (allocated(err)) ok = .false.
      call h5_table_append(tab2, row, err)
      if (allocated(err)) ok = .false.
      if (mod(i, 100) == 0) then
        call h5_table_flush(tab, err)
        if (allocated(err)) ok = .false.
      end if
    end do
    call check_true('append 1000 rows to two tables without error', ok)
    call check_true('h5_table_nrow = 1000', h5_table_nrow(tab) == nrows)
    call h5_table_close(tab, err)
    call ok_or_report('close '//table_file, err)
    call h5_table_close(tab2, err)
    call ok_or_report('close '//restart_file, err)
    elapsed = wall_time() - t0
    call check_le('create + 2000 appends + close (s)', elapsed, 0.5_dp)
    call h5_table_close(tab, err)
    call check_true('closing a closed table is a no-op', .not. allocated(err))
    call h5_table_append(tab, row, err)
    call check_true('append to a closed table gives an error', allocated(err))

    call read_table(table_file, a, names, nullpad)
    call check_true('table: Fortran shape (5, 1000)', all(shape(a) == [ncol, nrows]))
    ok = all(shape(a) == [ncol, nrows])
    if (ok) then
      do i = 1, nrows
        do j = 1, ncol
          if (.not. same_bits(a(j, i), val(i, j))) ok = .false.
        end do
      end do
    end if
    call check_true('table: all 5000 values bitwise exact', ok)
    call check_true('table: column names trimmed', size(names) == ncol)
    if (size(names) == ncol) then
      ok = .true.
      do j = 1, ncol
        if (names(j) /= trim(columns(j))) ok = .false.
      end do
      call check_true('table: column names '//join(names), ok)
    end if
    call check_true('table: names are null-padded fixed-length strings', nullpad)

    ! Restart: wrong column count and too many rows are refused; then keep 600, add 10.
    call h5_table_open_append(tab2, restart_file, ncol + 1, nkeep, err)
    call check_true('open_append with ncol=6 refused, message names the file', &
                    has_msg(err, restart_file))
    call h5_table_open_append(tab2, restart_file, ncol, nrows + 1, err)
    call check_true('open_append with nkeep=1001 refused, message names the file', &
                    has_msg(err, restart_file))
    call h5_table_open_append(tab2, restart_file, ncol, nkeep, err)
    call ok_or_report('open_append nkeep=600', err)
    call check_true('open_append: h5_table_nrow = 600', h5_table_nrow(tab2) == nkeep)
    ok = .true.
    do i = nkeep + 1, nkeep + nmore
      row = [(-val(i, j), j=1, ncol)]
      call h5_table_append(tab2, row, err)
      if (allocated(err)) ok = .false.
    end do
    call h5_table_flush(tab2, err)
    if (allocated(err)) ok = .false.
    call h5_table_close(tab2, err)
    if (allocated(err)) ok = .false.
    call check_true('append 10 rows after restart, flush, close', ok)

    call read_table(restart_file, a, names, nullpad)
    call check_true('restart: Fortran shape (5, 610)', all(shape(a) == [ncol, nkeep + nmore]))
    ok = all(shape(a) == [ncol, nkeep + nmore])
    if (ok) then
      do i = 1, nkeep
        do j = 1, ncol
          if (.not. same_bits(a(j, i), val(i, j))) ok = .false.
        end do
      end do
      do i = nkeep + 1, nkeep + nmore
        do j = 1, ncol
          if (.not. same_bits(a(j, i), -val(i, j))) ok = .false.
        end do
      end do
    end if
    call check_true('restart: rows 1-600 kept, rows 601-610 new, bitwise exact', ok)
    call check_true('restart: column names kept', size(names) == ncol)
  end subroutine test_table

  subroutine test_checkpoint()
    type(error_t), allocatable :: err
    real(dp), allocatable :: q(:), qd(:), qdd(:), q2(:), qd2(:), qdd2(:)
    integer, allocatable :: ints(:), ints2(:)
    real(dp), allocatable :: reals2(:)
    real(dp) :: t, t2
    integer :: step, step2, i, n
    logical :: exists

    n = 37
    allocate (q(n), qd(n), qdd(n))
    do i = 1, n
      q(i) = sin(real(i, dp))*10.0_dp**(i - 18)
      qd(i) = 1.0_dp/real(i, dp) - 0.5_dp
      qdd(i) = -exp(real(i, dp)/3.0_dp)
    end do
    q(1) = -0.0_dp
    q(2) = huge(1.0_dp)
    q(3) = tiny(1.0_dp)/8.0_dp   ! subnormal
    qd(5) = -huge(1.0_dp)
    t = 0.1_dp*3.0_dp
    step = 123456
    ints = [1, 0, -7, huge(1), -huge(1) - 1]

    ! A first checkpoint, then one overwriting it (the usual case during a run).
    call write_checkpoint(ckpt_file, 1.0_dp, 1, q + 1, qd, qdd, [integer ::], [real(dp) ::], err)
    call ok_or_report('write first checkpoint', err)
    call write_checkpoint(ckpt_file, t, step, q, qd, qdd, ints, [0.5_dp, -1.25_dp, huge(1._dp)], err)
    call ok_or_report('write second checkpoint over it', err)
    inquire (file=ckpt_file//'.part', exist=exists)
    call check_true('no .part file left behind', .not. exists)

    call read_checkpoint(ckpt_file, t2, step2, q2, qd2, qdd2, ints2, reals2, err)
    call ok_or_report('read checkpoint', err)
    call check_true('checkpoint: t bitwise equal', same_bits(t2, t))
    call check_true('checkpoint: step equal', step2 == step)
    call check_true('checkpoint: q bitwise equal (incl. -0, huge, subnormal)', &
                    same_bits_1d(q2, q))
    call check_true('checkpoint: qd bitwise equal', same_bits_1d(qd2, qd))
    call check_true('checkpoint: qdd bitwise equal', same_bits_1d(qdd2, qdd))
    call check_true('checkpoint: ints equal', allocated(ints2) .and. size(ints2) == size(ints))
    if (allocated(ints2)) call check_true('checkpoint: ints values', all(ints2 == ints))
    call check_true('checkpoint: reals round trip exactly', allocated(reals2) .and. size(reals2) == 3)
    if (allocated(reals2)) call check_true('checkpoint: reals values', &
                                           all(reals2 == [0.5_dp, -1.25_dp, huge(1._dp)]))

    ! Empty ints and ndof = 0 round trip.
    call write_checkpoint(ckpt_file, t, 0, q(1:0), qd(1:0), qdd(1:0), [integer ::], [real(dp) ::], err)
    call ok_or_report('write checkpoint with ndof=0, no ints', err)
    call read_checkpoint(ckpt_file, t2, step2, q2, qd2, qdd2, ints2, reals2, err)
    call ok_or_report('read checkpoint with ndof=0, no ints', err)
    call check_true('empty checkpoint: arrays allocated', allocated(q2) .and. allocated(ints2))
    if (allocated(q2) .and. allocated(ints2)) &
      call check_true('empty checkpoint: sizes are 0', size(q2) == 0 .and. size(ints2) == 0)

    call write_checkpoint(ckpt_file, t, step, q, qd(1:3), qdd, ints, [real(dp) ::], err)
    call check_true('write_checkpoint with size(qd) /= size(q) refused', has_msg(err, ckpt_file))
  end subroutine test_checkpoint

  subroutine test_errors()
    type(error_t), allocatable :: err
    type(h5_table_t) :: tab
    real(dp), allocatable :: q(:), qd(:), qdd(:), reals2(:)
    integer, allocatable :: ints(:)
    real(dp) :: t
    integer :: step, u

    open (newunit=u, file=text_file, status='replace', action='write')
    write (u, '(a)') 'this is not an HDF5 file'
    close (u)

    call read_checkpoint(missing_file, t, step, q, qd, qdd, ints, reals2, err)
    call check_true('read_checkpoint of a missing file: error naming the file', &
                    has_msg(err, missing_file))
    call show(err)
    call read_checkpoint(text_file, t, step, q, qd, qdd, ints, reals2, err)
    call check_true('read_checkpoint of a text file: error naming the file', &
                    has_msg(err, text_file))
    call show(err)
    call read_checkpoint(table_file, t, step, q, qd, qdd, ints, reals2, err)
    call check_true('read_checkpoint of a table file: missing dataset /t, naming the file', &
                    has_msg(err, table_file) .and. has_msg(err, '/t'))
    call show(err)
    call h5_table_open_append(tab, text_file, ncol, 0, err)
    call check_true('open_append of a text file: error naming the file', has_msg(err, text_file))
    call show(err)
    call h5_table_open_append(tab, ckpt_file, ncol, 0, err)
    call check_true('open_append of a checkpoint: missing /history, naming the file', &
                    has_msg(err, ckpt_file) .and. has_msg(err, '/history'))
    call show(err)
    call write_checkpoint('no_such_dir/ckpt.h5', 0.0_dp, 0, [1.0_dp], [1.0_dp], [1.0_dp], &
                          [integer ::], [real(dp) ::], err)
    call check_true('write_checkpoint into a missing folder: error naming the file', &
                    has_msg(err, 'no_such_dir/ckpt.h5'))
    call show(err)
    call h5_table_create(tab, 'no_such_dir/table.h5', columns, err)
    call check_true('h5_table_create into a missing folder: error naming the file', &
                    has_msg(err, 'no_such_dir/table.h5'))
    call show(err)
  end subroutine test_errors

  !> Every file, dataset, datatype and attribute the module opened (also on its error paths)
  !> has been closed again. (h5fget_obj_count_f on H5F_OBJ_ALL_F discounts the types that
  !> one h5open_f creates; every further h5open_f call would add another such set, which is
  !> why neither the module nor this test calls it more than once.)
  subroutine test_nothing_left_open()
    integer(size_t) :: n
    integer :: h
    call h5fget_obj_count_f(int(H5F_OBJ_ALL_F, hid_t), H5F_OBJ_ALL_F, n, h)
    if (n /= 0) print '(a,i0)', '  open HDF5 objects: ', n
    call check_true('no HDF5 object left open', h == 0 .and. n == 0)
  end subroutine test_nothing_left_open

  ! ---- reading a table back through the HDF5 API ----

  subroutine read_table(path, a, names, nullpad)
    character(len=*), intent(in) :: path
    real(dp), allocatable, intent(out) :: a(:, :)
    character(len=64), allocatable, intent(out) :: names(:)
    logical, intent(out) :: nullpad
    integer(hid_t) :: fid, dset, space, attr, atype, aspace
    integer(hsize_t) :: dims(2), maxdims(2), adims(1), amax(1)
    integer(size_t) :: slen
    integer :: h, ndims, strpad, i, k

    nullpad = .false.
    allocate (a(0, 0))
    allocate (names(0))
    ! (no h5open_f here: the module has opened the library, once, when creating the tables)
    call h5fopen_f(path, H5F_ACC_RDONLY_F, fid, h)
    if (h /= 0) return
    call h5dopen_f(fid, 'history', dset, h)
    call h5dget_space_f(dset, space, h)
    call h5sget_simple_extent_ndims_f(space, ndims, h)
    if (ndims == 2) then
      call h5sget_simple_extent_dims_f(space, dims, maxdims, h)
      deallocate (a)
      allocate (a(dims(1), dims(2)))
      call h5dread_f(dset, H5T_NATIVE_DOUBLE, a, dims, h)
    end if
    call h5sclose_f(space, h)

    call h5aopen_f(dset, 'columns', attr, h)
    if (h == 0) then
      call h5aget_type_f(attr, atype, h)
      call h5tget_size_f(atype, slen, h)
      call h5tget_strpad_f(atype, strpad, h)
      nullpad = strpad == H5T_STR_NULLPAD_F
      call h5aget_space_f(attr, aspace, h)
      call h5sget_simple_extent_dims_f(aspace, adims, amax, h)
      call h5sclose_f(aspace, h)
      deallocate (names)
      allocate (names(adims(1)))
      block
        character(len=slen) :: buf(adims(1))
        call h5aread_f(attr, atype, buf, adims, h)
        do i = 1, size(names)   ! cut at the first null
          k = index(buf(i), achar(0))
          if (k > 0) buf(i)(k:) = ' '
          names(i) = buf(i)
        end do
      end block
      call h5tclose_f(atype, h)
      call h5aclose_f(attr, h)
    end if
    call h5dclose_f(dset, h)
    call h5fclose_f(fid, h)
  end subroutine read_table

  ! ---- small helpers ----

  elemental logical function same_bits(x, y)
    real(dp), intent(in) :: x, y
    same_bits = transfer(x, 0_int64) == transfer(y, 0_int64)
  end function same_bits

  logical function same_bits_1d(x, y)
    real(dp), allocatable, intent(in) :: x(:)
    real(dp), intent(in) :: y(:)
    same_bits_1d = .false.
    if (.not. allocated(x)) return
    if (size(x) /= size(y)) return
    same_bits_1d = all(same_bits(x, y))
  end function same_bits_1d

  logical function has_msg(err, text)
    type(error_t), allocatable, intent(in) :: err
    character(len=*), intent(in) :: text
    has_msg = .false.
    if (allocated(err)) has_msg = index(err%message, text) > 0
  end function has_msg

  subroutine ok_or_report(what, err)
    character(len=*), intent(in) :: what
    type(error_t), allocatable, intent(in) :: err
    if (allocated(err)) then
      print '(a)', '  error: '//err%message
      call check_true(what, .false.)
    else
      call check_true(what, .true.)
    end if
  end subroutine ok_or_report

  subroutine show(err)
    type(error_t), allocatable, intent(in) :: err
    if (allocated(err)) print '(a)', '  message: '//err%message
  end subroutine show

  function join(names) result(s)
    character(len=*), intent(in) :: names(:)
    character(len=:), allocatable :: s
    integer :: i
    s = ''
    do i = 1, size(names)
      s = s//trim(names(i))
      if (i < size(names)) s = s//','
    end do
  end function join
end program test_hdf5_io
