!> HDF5 output: a growing time-history table and restart checkpoints.
!>
!> Serial HDF5 only: every routine here is called from MPI rank 0 alone (the caller guarantees
!> it), and no MPI-IO property list is used.
!>
!> The library is opened once, on first use (h5open_f), and its automatic error-stack printing
!> is switched off there, so failures reach the caller only as error_t messages that name the
!> file. It is never closed here: h5close_f would invalidate the handles of tables still open,
!> and the C library closes itself at program exit.
!>
!> Table file layout: one 2-D dataset "/history", Fortran shape (ncol, nrow) with nrow
!> unlimited and chunked, so Python (h5py, numpy C order) sees shape (nrow, ncol); its
!> attribute "columns" holds the column names as fixed-length, null-padded ASCII strings
!> (h5py returns a numpy array of bytes). Rows are extended and written one at a time; the
!> file is flushed to disk only by h5_table_flush (and close). A table made in_memory lives in
!> memory (HDF5's core driver) and h5_table_flush writes its image whole, to <path>.part
!> renamed onto <path>: the file on disk is always complete, and a full disk is an error
!> returned here (HDF5 itself, failing to write, leaves a file it cannot close and crashes
!> when the library shuts down).
!>
!> Checkpoint layout: scalar datasets "/t" (float64), "/step" and "/ndof" (int32), 1-D
!> datasets "/q", "/qd", "/qdd" (float64, ndof), "/ints" (int32) and "/reals" (float64), both possibly empty,
!> and "/fingerprint" (int32) when the caller gives one (the model's: casca_checkpoint). It is
!> made in memory and its image written to <path>.part, renamed onto <path> only when complete
!> and closed, so a crash or a full disk while writing never replaces a good checkpoint
!> (rename(2) is atomic on one file system).
module casca_hdf5_io
  use, intrinsic :: iso_c_binding, only: c_char, c_ptr, c_null_ptr, c_loc
  use hdf5, only: hid_t, hsize_t, size_t, h5open_f, h5eset_auto_f, h5fcreate_f, h5fopen_f, &
                  h5fclose_f, h5fflush_f, h5fis_hdf5_f, H5F_ACC_TRUNC_F, H5F_ACC_RDWR_F, &
                  H5F_ACC_RDONLY_F, H5F_SCOPE_GLOBAL_F, h5screate_f, h5screate_simple_f, &
                  h5sclose_f, h5sselect_hyperslab_f, h5sget_simple_extent_ndims_f, &
                  h5sget_simple_extent_dims_f, H5S_SCALAR_F, H5S_UNLIMITED_F, &
                  H5S_SELECT_SET_F, h5dcreate_f, h5dopen_f, h5dclose_f, h5dwrite_f, h5dread_f, &
                  h5dset_extent_f, h5dget_space_f, h5pcreate_f, h5pset_chunk_f, h5pclose_f, &
                  H5P_DATASET_CREATE_F, h5acreate_f, h5awrite_f, h5aclose_f, h5tcopy_f, &
                  h5tset_size_f, h5tset_strpad_f, h5tclose_f, H5T_NATIVE_CHARACTER, &
                  H5T_STR_NULLPAD_F, H5T_NATIVE_DOUBLE, H5T_NATIVE_INTEGER, H5T_IEEE_F64LE, &
                  H5T_STD_I32LE, h5lexists_f, H5P_FILE_ACCESS_F, h5pset_fapl_core_f, &
                  h5fget_file_image_f, h5get_libversion_f
  use casca_kinds, only: dp
  use casca_error, only: error_t, fatal_error
  use casca_checked_file, only: write_file_atomic
  use casca_strings, only: itoa
  implicit none
  private
  public :: h5_table_t, h5_table_create, h5_table_append, h5_table_flush, h5_table_close, &
            h5_table_open_append, h5_table_nrow, write_checkpoint, read_checkpoint, hdf5_version

  !> An open history table (opaque). Default-initialised = closed.
  type :: h5_table_t
    private
    integer(hid_t) :: file = -1_hid_t
    integer(hid_t) :: dset = -1_hid_t
    integer(hid_t) :: memspace = -1_hid_t    !< one row, (ncol), reused by every append
    integer :: ncol = 0
    integer(hsize_t) :: nrow = 0
    character(len=:), allocatable :: path
    logical :: is_open = .false.
    logical :: in_memory = .false.          !< flushed as a whole image (see above)
  end type h5_table_t

  character(len=*), parameter :: table_dset = 'history'
  character(len=*), parameter :: table_attr = 'columns'
  !> Target chunk size of the table, in bytes (a chunk is ncol x rows_per_chunk doubles).
  integer, parameter :: chunk_bytes = 65536

  logical, save :: h5_ready = .false.


contains

  ! ---------------------------------------------------------------------------------------
  ! Table
  ! ---------------------------------------------------------------------------------------

  !> Create (or overwrite) path with an empty table whose columns are named columns(:)
  !> (trailing blanks are not stored). tab must not be open.
  subroutine h5_table_create(tab, path, columns, err, in_memory)
    type(h5_table_t), intent(inout) :: tab
    character(len=*), intent(in) :: path
    character(len=*), intent(in) :: columns(:)
    type(error_t), allocatable, intent(out) :: err
    logical, intent(in), optional :: in_memory

    character(len=*), parameter :: who = 'h5_table_create'
    integer(hid_t) :: fid, space, plist, dset, strtype, aspace, attr, memspace
    integer(hsize_t) :: dims(2), maxdims(2), chunk(2)
    integer :: ncol, maxlen, i, h

    if (tab%is_open) then
      call fatal_error(err, who//': '//path//': the table is still open on '//tab%path)
      return
    end if
    ncol = size(columns)
    if (ncol < 1) then
      call fatal_error(err, who//': '//path//': at least one column is needed')
      return
    end if
    call ensure_open(who, path, err)
    if (allocated(err)) return

    tab%in_memory = .false.
    if (present(in_memory)) tab%in_memory = in_memory
    call create_file(who, path, tab%in_memory, fid, err)
    if (allocated(err)) return

    dims = [int(ncol, hsize_t), 0_hsize_t]
    maxdims = [int(ncol, hsize_t), H5S_UNLIMITED_F]
    chunk = [int(ncol, hsize_t), int(max(16, chunk_bytes/(8*ncol)), hsize_t)]
    dset = -1; space = -1; plist = -1
    call h5screate_simple_f(2, dims, space, h, maxdims)
    if (h == 0) call h5pcreate_f(H5P_DATASET_CREATE_F, plist, h)
    if (h == 0) call h5pset_chunk_f(plist, 2, chunk, h)
    if (h == 0) call h5dcreate_f(fid, table_dset, H5T_IEEE_F64LE, space, dset, h, plist)
    if (plist /= -1) call h5pclose_f(plist, i)
    if (space /= -1) call h5sclose_f(space, i)
    if (h /= 0) then
      call fatal_error(err, who//': '//path//': cannot create dataset /'//table_dset)
      call abandon(fid, dset)
      return
    end if

    ! Column names: fixed-length strings, null padded, written with no conversion.
    maxlen = max(1, maxval(len_trim(columns)))
    strtype = -1; aspace = -1; attr = -1
    call h5tcopy_f(H5T_NATIVE_CHARACTER, strtype, h)
    if (h == 0) call h5tset_size_f(strtype, int(maxlen, size_t), h)
    if (h == 0) call h5tset_strpad_f(strtype, H5T_STR_NULLPAD_F, h)
    if (h == 0) call h5screate_simple_f(1, dims(1:1), aspace, h)
    if (h == 0) call h5acreate_f(dset, table_attr, strtype, aspace, attr, h)
    if (h == 0) then
      block
        character(len=maxlen) :: names(ncol)
        do i = 1, ncol
          names(i) = repeat(achar(0), maxlen)
          names(i)(1:len_trim(columns(i))) = columns(i)(1:len_trim(columns(i)))
        end do
        call h5awrite_f(attr, strtype, names, dims(1:1), h)
      end block
    end if
    if (attr /= -1) call h5aclose_f(attr, i)
    if (aspace /= -1) call h5sclose_f(aspace, i)
    if (strtype /= -1) call h5tclose_f(strtype, i)
    if (h /= 0) then
      call fatal_error(err, who//': '//path//': cannot write attribute "'//table_attr// &
                       '" on /'//table_dset)
      call abandon(fid, dset)
      return
    end if

    call h5screate_simple_f(1, dims(1:1), memspace, h)
    if (h /= 0) then
      call fatal_error(err, who//': '//path//': cannot create the row dataspace')
      call abandon(fid, dset)
      return
    end if
    call h5fflush_f(fid, H5F_SCOPE_GLOBAL_F, h)   ! an empty table is a valid file at once

    tab%file = fid
    tab%dset = dset
    tab%memspace = memspace
    tab%ncol = ncol
    tab%nrow = 0
    tab%path = path
    tab%is_open = .true.
  end subroutine h5_table_create

  !> Reopen the table of a previous run in path: it must have ncol columns; it is cut to its
  !> first nkeep rows (0 <= nkeep <= rows in the file) and further appends go after them.
  subroutine h5_table_open_append(tab, path, ncol, nkeep, err)
    type(h5_table_t), intent(inout) :: tab
    character(len=*), intent(in) :: path
    integer, intent(in) :: ncol, nkeep
    type(error_t), allocatable, intent(out) :: err

    character(len=*), parameter :: who = 'h5_table_open_append'
    integer(hid_t) :: fid, dset, memspace
    integer(hsize_t) :: dims(2)
    integer :: h, i

    if (tab%is_open) then
      call fatal_error(err, who//': '//path//': the table is still open on '//tab%path)
      return
    end if
    call open_existing(who, path, .true., fid, err)
    if (allocated(err)) return

    dset = -1
    call open_dataset(who, path, fid, table_dset, dset, err)
    if (allocated(err)) then
      call abandon(fid, dset)
      return
    end if
    call dataset_dims(who, path, dset, table_dset, 2, dims, err)
    if (allocated(err)) then
      call abandon(fid, dset)
      return
    end if
    if (dims(1) /= int(ncol, hsize_t)) then
      call fatal_error(err, who//': '//path//': /'//table_dset//' has '//itoa(dims(1))// &
                       ' columns, expected '//itoa(int(ncol, hsize_t)))
      call abandon(fid, dset)
      return
    end if
    if (nkeep < 0 .or. int(nkeep, hsize_t) > dims(2)) then
      call fatal_error(err, who//': '//path//': cannot keep '//itoa(int(nkeep, hsize_t))// &
                       ' rows, /'//table_dset//' has '//itoa(dims(2)))
      call abandon(fid, dset)
      return
    end if

    dims(2) = int(nkeep, hsize_t)
    call h5dset_extent_f(dset, dims, h)
    if (h /= 0) then
      call fatal_error(err, who//': '//path//': cannot truncate /'//table_dset//' to '// &
                       itoa(dims(2))//' rows')
      call abandon(fid, dset)
      return
    end if
    call h5screate_simple_f(1, dims(1:1), memspace, h)
    if (h /= 0) then
      call fatal_error(err, who//': '//path//': cannot create the row dataspace')
      call abandon(fid, dset)
      return
    end if
    call h5fflush_f(fid, H5F_SCOPE_GLOBAL_F, i)

    tab%file = fid
    tab%dset = dset
    tab%memspace = memspace
    tab%ncol = ncol
    tab%nrow = dims(2)
    tab%path = path
    tab%is_open = .true.
  end subroutine h5_table_open_append

  !> Add one row (size ncol) at the end of the table. Not flushed: see h5_table_flush.
  subroutine h5_table_append(tab, row, err)
    type(h5_table_t), intent(inout) :: tab
    real(dp), intent(in) :: row(:)
    type(error_t), allocatable, intent(out) :: err

    character(len=*), parameter :: who = 'h5_table_append'
    integer(hid_t) :: fspace
    integer(hsize_t) :: dims(2), offset(2), count(2)
    integer :: h, i

    if (.not. tab%is_open) then
      call fatal_error(err, who//': the table is not open')
      return
    end if
    if (size(row) /= tab%ncol) then
      call fatal_error(err, who//': '//tab%path//': row has '//itoa(int(size(row), hsize_t)) &
                       //' values, the table has '//itoa(int(tab%ncol, hsize_t))//' columns')
      return
    end if

    dims = [int(tab%ncol, hsize_t), tab%nrow + 1]
    call h5dset_extent_f(tab%dset, dims, h)
    if (h /= 0) then
      call fatal_error(err, who//': '//tab%path//': cannot extend /'//table_dset//' to '// &
                       itoa(dims(2))//' rows')
      return
    end if
    tab%nrow = dims(2)   ! the file has the row now (fill value 0 if the write below fails)

    offset = [0_hsize_t, tab%nrow - 1]
    count = [int(tab%ncol, hsize_t), 1_hsize_t]
    call h5dget_space_f(tab%dset, fspace, h)
    if (h == 0) then
      call h5sselect_hyperslab_f(fspace, H5S_SELECT_SET_F, offset, count, h)
      if (h == 0) call h5dwrite_f(tab%dset, H5T_NATIVE_DOUBLE, row, count(1:1), h, &
                                  tab%memspace, fspace)
      call h5sclose_f(fspace, i)
    end if
    if (h /= 0) then
      call fatal_error(err, who//': '//tab%path//': cannot write row '//itoa(tab%nrow))
      return
    end if
  end subroutine h5_table_append

  !> Push everything appended so far to the file (a reader then sees those rows).
  subroutine h5_table_flush(tab, err)
    type(h5_table_t), intent(inout) :: tab
    type(error_t), allocatable, intent(out) :: err
    integer :: h

    if (.not. tab%is_open) then
      call fatal_error(err, 'h5_table_flush: the table is not open')
      return
    end if
    if (tab%in_memory) then
      call save_image('h5_table_flush', tab%path, tab%file, err)
      return
    end if
    call h5fflush_f(tab%file, H5F_SCOPE_GLOBAL_F, h)
    if (h /= 0) call fatal_error(err, 'h5_table_flush: '//tab%path//': flush failed')
  end subroutine h5_table_flush

  !> Close the table (and flush it). Closing a table that is not open does nothing.
  subroutine h5_table_close(tab, err)
    type(h5_table_t), intent(inout) :: tab
    type(error_t), allocatable, intent(out) :: err
    integer :: h1, h2, h3

    if (.not. tab%is_open) return
    if (tab%in_memory) call save_image('h5_table_close', tab%path, tab%file, err)
    call h5sclose_f(tab%memspace, h1)
    call h5dclose_f(tab%dset, h2)
    call h5fclose_f(tab%file, h3)
    if ((h1 /= 0 .or. h2 /= 0 .or. h3 /= 0) .and. .not. allocated(err)) &
      call fatal_error(err, 'h5_table_close: '//tab%path//': error closing the file')
    tab%file = -1
    tab%dset = -1
    tab%memspace = -1
    tab%ncol = 0
    tab%nrow = 0
    tab%is_open = .false.
  end subroutine h5_table_close

  !> Number of rows in the table (0 if not open).
  pure integer function h5_table_nrow(tab) result(n)
    type(h5_table_t), intent(in) :: tab
    n = int(tab%nrow)
  end function h5_table_nrow

  ! ---------------------------------------------------------------------------------------
  ! Checkpoint
  ! ---------------------------------------------------------------------------------------

  !> Write a restart checkpoint to path (via path.part, renamed when complete).
  !> q, qd, qdd must have the same size ndof; ints and reals (the caller's extra state) may
  !> have any size, including 0.
  subroutine write_checkpoint(path, t, step, q, qd, qdd, ints, reals, err, fingerprint, dt_next, &
                              checksum, dt_cap, pressure_work, last)
    character(len=*), intent(in) :: path
    real(dp), intent(in) :: t
    integer, intent(in) :: step
    real(dp), intent(in) :: q(:), qd(:), qdd(:)
    integer, intent(in) :: ints(:)
    real(dp), intent(in) :: reals(:)
    type(error_t), allocatable, intent(out) :: err
    integer, intent(in), optional :: fingerprint(:)
    real(dp), intent(in), optional :: dt_next   !< the next step's length (error-controlled runs)
    integer, intent(in), optional :: checksum(:)
    real(dp), intent(in), optional :: dt_cap(:) !< the energy's cap on the steps, when set, last step's energy
    real(dp), intent(in), optional :: pressure_work   !< the pressures' on open surfaces so far
    real(dp), intent(in), optional :: last(:)   !< the last step's length and start acceleration (empty: none)

    character(len=*), parameter :: who = 'write_checkpoint'
    integer(hid_t) :: fid
    integer :: h

    if (size(qd) /= size(q) .or. size(qdd) /= size(q)) then
      call fatal_error(err, who//': '//path//': q, qd, qdd have sizes '// &
                       itoa(int(size(q), hsize_t))//', '//itoa(int(size(qd), hsize_t))// &
                       ', '//itoa(int(size(qdd), hsize_t))//' (must be equal)')
      return
    end if
    call ensure_open(who, path, err)
    if (allocated(err)) return

    call create_file(who, path, .true., fid, err)
    if (allocated(err)) return
    call put_real_scalar(who, path, fid, 't', t, err)
    if (.not. allocated(err)) call put_int_scalar(who, path, fid, 'step', step, err)
    if (.not. allocated(err)) call put_int_scalar(who, path, fid, 'ndof', size(q), err)
    if (.not. allocated(err)) call put_real_1d(who, path, fid, 'q', q, err)
    if (.not. allocated(err)) call put_real_1d(who, path, fid, 'qd', qd, err)
    if (.not. allocated(err)) call put_real_1d(who, path, fid, 'qdd', qdd, err)
    if (.not. allocated(err)) call put_int_1d(who, path, fid, 'ints', ints, err)
    if (.not. allocated(err)) call put_real_1d(who, path, fid, 'reals', reals, err)
    if (present(fingerprint) .and. .not. allocated(err)) &
      call put_int_1d(who, path, fid, 'fingerprint', fingerprint, err)
    if (present(dt_next) .and. .not. allocated(err)) &
      call put_real_scalar(who, path, fid, 'dt_next', dt_next, err)
    if (present(checksum) .and. .not. allocated(err)) &
      call put_int_1d(who, path, fid, 'checksum', checksum, err)
    if (present(dt_cap) .and. .not. allocated(err)) &
      call put_real_1d(who, path, fid, 'dt_cap', dt_cap, err)
    if (present(pressure_work) .and. .not. allocated(err)) &
      call put_real_scalar(who, path, fid, 'pressure_work', pressure_work, err)
    if (present(last) .and. .not. allocated(err)) then
      if (size(last) > 0) call put_real_1d(who, path, fid, 'last', last, err)
    end if
    if (.not. allocated(err)) call save_image(who, path, fid, err)
    call h5fclose_f(fid, h)   ! (in memory: nothing to fail on)
  end subroutine write_checkpoint

  !> Read a checkpoint written by write_checkpoint (fingerprint, checksum: not allocated if it
  !> has none; dt_next: 0 if it has none; dt_cap, pressure_work, last: not allocated if it has none).
  subroutine read_checkpoint(path, t, step, q, qd, qdd, ints, reals, err, fingerprint, dt_next, &
                             checksum, dt_cap, pressure_work, last)
    character(len=*), intent(in) :: path
    real(dp), intent(out) :: t
    integer, intent(out) :: step
    real(dp), allocatable, intent(out) :: q(:), qd(:), qdd(:)
    integer, allocatable, intent(out) :: ints(:)
    real(dp), allocatable, intent(out) :: reals(:)
    type(error_t), allocatable, intent(out) :: err
    integer, allocatable, intent(out), optional :: fingerprint(:)
    real(dp), intent(out), optional :: dt_next
    integer, allocatable, intent(out), optional :: checksum(:)
    real(dp), allocatable, intent(out), optional :: dt_cap(:)
    real(dp), allocatable, intent(out), optional :: pressure_work
    real(dp), allocatable, intent(out), optional :: last(:)

    character(len=*), parameter :: who = 'read_checkpoint'
    integer(hid_t) :: fid
    integer :: ndof, h
    logical :: has_fp, has_dt

    t = 0
    step = 0
    call open_existing(who, path, .false., fid, err)
    if (allocated(err)) return
    call get_real_scalar(who, path, fid, 't', t, err)
    if (.not. allocated(err)) call get_int_scalar(who, path, fid, 'step', step, err)
    if (.not. allocated(err)) call get_int_scalar(who, path, fid, 'ndof', ndof, err)
    if (.not. allocated(err)) call get_real_1d(who, path, fid, 'q', q, err)
    if (.not. allocated(err)) call get_real_1d(who, path, fid, 'qd', qd, err)
    if (.not. allocated(err)) call get_real_1d(who, path, fid, 'qdd', qdd, err)
    if (.not. allocated(err)) call get_int_1d(who, path, fid, 'ints', ints, err)
    if (.not. allocated(err)) call get_real_1d(who, path, fid, 'reals', reals, err)
    if (present(fingerprint) .and. .not. allocated(err)) then
      call h5lexists_f(fid, 'fingerprint', has_fp, h)
      if (h == 0 .and. has_fp) call get_int_1d(who, path, fid, 'fingerprint', fingerprint, err)
    end if
    if (present(checksum) .and. .not. allocated(err)) then
      call h5lexists_f(fid, 'checksum', has_fp, h)
      if (h == 0 .and. has_fp) call get_int_1d(who, path, fid, 'checksum', checksum, err)
    end if
    if (present(dt_next)) then
      dt_next = 0
      if (.not. allocated(err)) then
        call h5lexists_f(fid, 'dt_next', has_dt, h)
        if (h == 0 .and. has_dt) call get_real_scalar(who, path, fid, 'dt_next', dt_next, err)
      end if
    end if
    if (present(dt_cap) .and. .not. allocated(err)) then
      call h5lexists_f(fid, 'dt_cap', has_dt, h)
      if (h == 0 .and. has_dt) call get_real_1d(who, path, fid, 'dt_cap', dt_cap, err)
    end if
    if (present(pressure_work) .and. .not. allocated(err)) then
      call h5lexists_f(fid, 'pressure_work', has_dt, h)
      if (h == 0 .and. has_dt) then
        allocate (pressure_work)
        call get_real_scalar(who, path, fid, 'pressure_work', pressure_work, err)
      end if
    end if
    if (present(last) .and. .not. allocated(err)) then
      call h5lexists_f(fid, 'last', has_dt, h)
      if (h == 0 .and. has_dt) call get_real_1d(who, path, fid, 'last', last, err)
    end if
    call h5fclose_f(fid, h)
    if (allocated(err)) return
    if (size(q) /= ndof .or. size(qd) /= ndof .or. size(qdd) /= ndof) then
      call fatal_error(err, who//': '//path//': /q, /qd, /qdd have sizes '// &
                       itoa(int(size(q), hsize_t))//', '//itoa(int(size(qd), hsize_t))// &
                       ', '//itoa(int(size(qdd), hsize_t))//' but /ndof is '// &
                       itoa(int(ndof, hsize_t)))
      return
    end if
  end subroutine read_checkpoint

  ! ---------------------------------------------------------------------------------------
  ! Helpers
  ! ---------------------------------------------------------------------------------------

  !> Create the HDF5 file path: on disk, or in memory only (core driver, no backing store:
  !> save_image writes it).
  subroutine create_file(who, path, in_memory, fid, err)
    character(len=*), intent(in) :: who, path
    logical, intent(in) :: in_memory
    integer(hid_t), intent(out) :: fid
    type(error_t), allocatable, intent(out) :: err
    integer(hid_t) :: fapl
    integer :: h, i
    if (in_memory) then
      call h5pcreate_f(H5P_FILE_ACCESS_F, fapl, h)
      if (h == 0) call h5pset_fapl_core_f(fapl, int(1048576, size_t), .false., h)
      if (h == 0) call h5fcreate_f(path, H5F_ACC_TRUNC_F, fid, h, access_prp=fapl)
      call h5pclose_f(fapl, i)
    else
      call h5fcreate_f(path, H5F_ACC_TRUNC_F, fid, h)
    end if
    if (h /= 0) call fatal_error(err, who//': cannot create HDF5 file '//path)
  end subroutine create_file

  !> Write the image of the in-memory file fid to path (via path.part, renamed when complete).
  subroutine save_image(who, path, fid, err)
    character(len=*), intent(in) :: who, path
    integer(hid_t), intent(in) :: fid
    type(error_t), allocatable, intent(out) :: err
    character(kind=c_char), allocatable, target :: image(:)
    type(c_ptr) :: buf
    integer(size_t) :: n
    integer :: h
    buf = c_null_ptr
    call h5fflush_f(fid, H5F_SCOPE_GLOBAL_F, h)   ! the image holds only flushed metadata
    if (h == 0) call h5fget_file_image_f(fid, buf, 0_size_t, h, n)
    if (h == 0) then
      allocate (image(n))
      buf = c_loc(image)
      call h5fget_file_image_f(fid, buf, n, h)
    end if
    if (h /= 0) then
      call fatal_error(err, who//': '//path//': cannot make the file image'); return
    end if
    call write_file_atomic(path, image, err)
    if (allocated(err)) err%message = who//': '//err%message
  end subroutine save_image

  !> Open the HDF5 library once per run and silence its error-stack printing.
  subroutine ensure_open(who, path, err)
    character(len=*), intent(in) :: who, path
    type(error_t), allocatable, intent(out) :: err
    integer :: h
    if (h5_ready) return
    call h5open_f(h)
    if (h /= 0) then
      call fatal_error(err, who//': '//path//': cannot initialise the HDF5 library')
      return
    end if
    call h5eset_auto_f(0, h)
    h5_ready = .true.
  end subroutine ensure_open

  !> Open an existing HDF5 file (read-only or read-write) with distinct messages for a
  !> missing file, a file that is not HDF5, and an HDF5 file that cannot be opened.
  subroutine open_existing(who, path, rdwr, fid, err)
    character(len=*), intent(in) :: who, path
    logical, intent(in) :: rdwr
    integer(hid_t), intent(out) :: fid
    type(error_t), allocatable, intent(out) :: err
    logical :: exists, is_h5
    integer :: h

    fid = -1
    inquire (file=path, exist=exists)
    if (.not. exists) then
      call fatal_error(err, who//': cannot open '//path//': no such file')
      return
    end if
    call ensure_open(who, path, err)
    if (allocated(err)) return
    call h5fis_hdf5_f(path, is_h5, h)
    if (h /= 0) then
      call fatal_error(err, who//': cannot read '//path)
      return
    end if
    if (.not. is_h5) then
      call fatal_error(err, who//': '//path//' is not an HDF5 file')
      return
    end if
    if (rdwr) then
      call h5fopen_f(path, H5F_ACC_RDWR_F, fid, h)
    else
      call h5fopen_f(path, H5F_ACC_RDONLY_F, fid, h)
    end if
    if (h /= 0) then
      if (rdwr) then
        call fatal_error(err, who//': cannot open HDF5 file '//path//' for writing ' &
                         //'(read-only, or open elsewhere?)')
      else
        call fatal_error(err, who//': cannot open HDF5 file '//path)
      end if
      fid = -1
    end if
  end subroutine open_existing

  !> Open dataset /name, with a clear message if it is missing.
  subroutine open_dataset(who, path, fid, name, dset, err)
    character(len=*), intent(in) :: who, path, name
    integer(hid_t), intent(in) :: fid
    integer(hid_t), intent(out) :: dset
    type(error_t), allocatable, intent(out) :: err
    logical :: exists
    integer :: h

    dset = -1
    call h5lexists_f(fid, name, exists, h)
    if (h /= 0 .or. .not. exists) then
      call fatal_error(err, who//': '//path//': missing dataset /'//name)
      return
    end if
    call h5dopen_f(fid, name, dset, h)
    if (h /= 0) then
      dset = -1
      call fatal_error(err, who//': '//path//': cannot open dataset /'//name)
    end if
  end subroutine open_dataset

  !> The Fortran-order dimensions of an open dataset, which must have the given rank
  !> (rank 0 = scalar).
  subroutine dataset_dims(who, path, dset, name, rank, dims, err)
    character(len=*), intent(in) :: who, path, name
    integer(hid_t), intent(in) :: dset
    integer, intent(in) :: rank
    integer(hsize_t), intent(out) :: dims(:)
    type(error_t), allocatable, intent(out) :: err
    integer(hid_t) :: space
    integer(hsize_t) :: maxdims(max(1, size(dims)))
    integer :: ndims, h, i

    dims = 0
    call h5dget_space_f(dset, space, h)
    if (h /= 0) then
      call fatal_error(err, who//': '//path//': cannot read the shape of /'//name)
      return
    end if
    call h5sget_simple_extent_ndims_f(space, ndims, h)
    if (h == 0 .and. ndims == rank .and. rank > 0) &
      call h5sget_simple_extent_dims_f(space, dims, maxdims, h)
    call h5sclose_f(space, i)
    if (h < 0) then   ! (h5sget_simple_extent_dims_f returns the rank on success)
      call fatal_error(err, who//': '//path//': cannot read the shape of /'//name)
    else if (ndims /= rank) then
      call fatal_error(err, who//': '//path//': /'//name//' has rank '// &
                       itoa(int(ndims, hsize_t))//', expected '//itoa(int(rank, hsize_t)))
    end if
  end subroutine dataset_dims

  subroutine put_real_scalar(who, path, fid, name, x, err)
    character(len=*), intent(in) :: who, path, name
    integer(hid_t), intent(in) :: fid
    real(dp), intent(in) :: x
    type(error_t), allocatable, intent(out) :: err
    integer(hid_t) :: space, dset
    integer(hsize_t), parameter :: one(1) = [1_hsize_t]
    integer :: h, i
    dset = -1
    call h5screate_f(H5S_SCALAR_F, space, h)
    if (h /= 0) then
      call fatal_error(err, who//': '//path//': cannot create dataset /'//name)
      return
    end if
    call h5dcreate_f(fid, name, H5T_IEEE_F64LE, space, dset, h)
    if (h == 0) call h5dwrite_f(dset, H5T_NATIVE_DOUBLE, x, one, h)
    if (dset /= -1) call h5dclose_f(dset, i)
    call h5sclose_f(space, i)
    if (h /= 0) call fatal_error(err, who//': '//path//': cannot write dataset /'//name)
  end subroutine put_real_scalar

  subroutine put_int_scalar(who, path, fid, name, n, err)
    character(len=*), intent(in) :: who, path, name
    integer(hid_t), intent(in) :: fid
    integer, intent(in) :: n
    type(error_t), allocatable, intent(out) :: err
    integer(hid_t) :: space, dset
    integer(hsize_t), parameter :: one(1) = [1_hsize_t]
    integer :: h, i
    dset = -1
    call h5screate_f(H5S_SCALAR_F, space, h)
    if (h /= 0) then
      call fatal_error(err, who//': '//path//': cannot create dataset /'//name)
      return
    end if
    call h5dcreate_f(fid, name, H5T_STD_I32LE, space, dset, h)
    if (h == 0) call h5dwrite_f(dset, H5T_NATIVE_INTEGER, n, one, h)
    if (dset /= -1) call h5dclose_f(dset, i)
    call h5sclose_f(space, i)
    if (h /= 0) call fatal_error(err, who//': '//path//': cannot write dataset /'//name)
  end subroutine put_int_scalar

  subroutine put_real_1d(who, path, fid, name, x, err)
    character(len=*), intent(in) :: who, path, name
    integer(hid_t), intent(in) :: fid
    real(dp), intent(in) :: x(:)
    type(error_t), allocatable, intent(out) :: err
    integer(hid_t) :: space, dset
    integer(hsize_t) :: dims(1)
    integer :: h, i
    dset = -1
    dims = int(size(x), hsize_t)
    call h5screate_simple_f(1, dims, space, h)
    if (h /= 0) then
      call fatal_error(err, who//': '//path//': cannot create dataset /'//name)
      return
    end if
    call h5dcreate_f(fid, name, H5T_IEEE_F64LE, space, dset, h)
    if (h == 0 .and. size(x) > 0) call h5dwrite_f(dset, H5T_NATIVE_DOUBLE, x, dims, h)
    if (dset /= -1) call h5dclose_f(dset, i)
    call h5sclose_f(space, i)
    if (h /= 0) call fatal_error(err, who//': '//path//': cannot write dataset /'//name)
  end subroutine put_real_1d

  subroutine put_int_1d(who, path, fid, name, x, err)
    character(len=*), intent(in) :: who, path, name
    integer(hid_t), intent(in) :: fid
    integer, intent(in) :: x(:)
    type(error_t), allocatable, intent(out) :: err
    integer(hid_t) :: space, dset
    integer(hsize_t) :: dims(1)
    integer :: h, i
    dset = -1
    dims = int(size(x), hsize_t)
    call h5screate_simple_f(1, dims, space, h)
    if (h /= 0) then
      call fatal_error(err, who//': '//path//': cannot create dataset /'//name)
      return
    end if
    call h5dcreate_f(fid, name, H5T_STD_I32LE, space, dset, h)
    if (h == 0 .and. size(x) > 0) call h5dwrite_f(dset, H5T_NATIVE_INTEGER, x, dims, h)
    if (dset /= -1) call h5dclose_f(dset, i)
    call h5sclose_f(space, i)
    if (h /= 0) call fatal_error(err, who//': '//path//': cannot write dataset /'//name)
  end subroutine put_int_1d

  subroutine get_real_scalar(who, path, fid, name, x, err)
    character(len=*), intent(in) :: who, path, name
    integer(hid_t), intent(in) :: fid
    real(dp), intent(out) :: x
    type(error_t), allocatable, intent(out) :: err
    integer(hid_t) :: dset
    integer(hsize_t) :: dims(1)
    integer :: h, i
    x = 0
    call open_dataset(who, path, fid, name, dset, err)
    if (allocated(err)) return
    call dataset_dims(who, path, dset, name, 0, dims, err)
    if (.not. allocated(err)) then
      dims = 1
      call h5dread_f(dset, H5T_NATIVE_DOUBLE, x, dims, h)
      if (h /= 0) call fatal_error(err, who//': '//path//': cannot read dataset /'//name)
    end if
    call h5dclose_f(dset, i)
  end subroutine get_real_scalar

  subroutine get_int_scalar(who, path, fid, name, n, err)
    character(len=*), intent(in) :: who, path, name
    integer(hid_t), intent(in) :: fid
    integer, intent(out) :: n
    type(error_t), allocatable, intent(out) :: err
    integer(hid_t) :: dset
    integer(hsize_t) :: dims(1)
    integer :: h, i
    n = 0
    call open_dataset(who, path, fid, name, dset, err)
    if (allocated(err)) return
    call dataset_dims(who, path, dset, name, 0, dims, err)
    if (.not. allocated(err)) then
      dims = 1
      call h5dread_f(dset, H5T_NATIVE_INTEGER, n, dims, h)
      if (h /= 0) call fatal_error(err, who//': '//path//': cannot read dataset /'//name)
    end if
    call h5dclose_f(dset, i)
  end subroutine get_int_scalar

  subroutine get_real_1d(who, path, fid, name, x, err)
    character(len=*), intent(in) :: who, path, name
    integer(hid_t), intent(in) :: fid
    real(dp), allocatable, intent(out) :: x(:)
    type(error_t), allocatable, intent(out) :: err
    integer(hid_t) :: dset
    integer(hsize_t) :: dims(1)
    integer :: h, i
    call open_dataset(who, path, fid, name, dset, err)
    if (allocated(err)) return
    call dataset_dims(who, path, dset, name, 1, dims, err)
    if (.not. allocated(err)) then
      allocate (x(dims(1)), stat=h)   ! a damaged file may claim any size
      if (h /= 0) then
        allocate (x(0))
        call too_large(who, path, name, dims(1), err)
      else
        if (dims(1) > 0) call h5dread_f(dset, H5T_NATIVE_DOUBLE, x, dims, h)
        if (h /= 0) call fatal_error(err, who//': '//path//': cannot read dataset /'//name)
      end if
    end if
    call h5dclose_f(dset, i)
  end subroutine get_real_1d

  subroutine get_int_1d(who, path, fid, name, x, err)
    character(len=*), intent(in) :: who, path, name
    integer(hid_t), intent(in) :: fid
    integer, allocatable, intent(out) :: x(:)
    type(error_t), allocatable, intent(out) :: err
    integer(hid_t) :: dset
    integer(hsize_t) :: dims(1)
    integer :: h, i
    call open_dataset(who, path, fid, name, dset, err)
    if (allocated(err)) return
    call dataset_dims(who, path, dset, name, 1, dims, err)
    if (.not. allocated(err)) then
      allocate (x(dims(1)), stat=h)   ! a damaged file may claim any size
      if (h /= 0) then
        allocate (x(0))
        call too_large(who, path, name, dims(1), err)
      else
        if (dims(1) > 0) call h5dread_f(dset, H5T_NATIVE_INTEGER, x, dims, h)
        if (h /= 0) call fatal_error(err, who//': '//path//': cannot read dataset /'//name)
      end if
    end if
    call h5dclose_f(dset, i)
  end subroutine get_int_1d

  !> The error of a dataset whose claimed size cannot be allocated
  subroutine too_large(who, path, name, n, err)
    character(len=*), intent(in) :: who, path, name
    integer(hsize_t), intent(in) :: n
    type(error_t), allocatable, intent(out) :: err
    call fatal_error(err, who//': '//path//': /'//name//' claims '//itoa(n)// &
                     ' values, more than fit in memory')
  end subroutine too_large

  !> Close a half-built file after an error (ids of -1 are skipped).
  subroutine abandon(fid, dset)
    integer(hid_t), intent(in) :: fid, dset
    integer :: h
    if (dset /= -1) call h5dclose_f(dset, h)
    if (fid /= -1) call h5fclose_f(fid, h)
  end subroutine abandon


  !> The linked HDF5 library's version, e.g. "1.10.8" (casca --version)
  function hdf5_version() result(s)
    character(len=:), allocatable :: s
    integer :: major, minor, release, hdferr
    call h5get_libversion_f(major, minor, release, hdferr)
    if (hdferr /= 0) then
      s = 'unknown'
    else
      s = itoa(major)//'.'//itoa(minor)//'.'//itoa(release)
    end if
  end function hdf5_version
end module casca_hdf5_io
