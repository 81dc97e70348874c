!> Files written through C's stdio, whose fwrite, fflush and fclose report a full disk:
!> gfortran's WRITE, FLUSH and CLOSE lose that error for data still in their buffer (a frame
!> of 0 bytes was then renamed onto its final name as if complete). Every call here is
!> checked and its failure returned as an error naming the file.
module casca_checked_file
  use, intrinsic :: iso_c_binding, only: c_char, c_int, c_size_t, c_ptr, c_null_ptr, &
                                         c_null_char, c_associated
  use casca_error, only: error_t, fatal_error
  use casca_files, only: rename_file, delete_file
  implicit none
  private
  public :: checked_file_t, cf_open, cf_write, cf_flush, cf_close, cf_discard, write_file_atomic

  !> write text (a string) or bytes (an array of characters, such as a file image)
  interface cf_write
    module procedure cf_write_text, cf_write_bytes
  end interface cf_write

  interface write_file_atomic
    module procedure write_text_atomic, write_bytes_atomic
  end interface write_file_atomic

  type :: checked_file_t
    type(c_ptr) :: fp = c_null_ptr
    character(len=:), allocatable :: path
  end type checked_file_t

  character(len=*), parameter :: full = ' (is the disk full?)'

  interface
    function c_fopen(path, mode) bind(c, name='fopen') result(fp)
      import :: c_char, c_ptr
      character(kind=c_char), intent(in) :: path(*), mode(*)
      type(c_ptr) :: fp
    end function c_fopen

    function c_fwrite(buf, size, n, fp) bind(c, name='fwrite') result(written)
      import :: c_char, c_size_t, c_ptr
      character(kind=c_char), intent(in) :: buf(*)
      integer(c_size_t), value :: size, n
      type(c_ptr), value :: fp
      integer(c_size_t) :: written
    end function c_fwrite

    function c_fflush(fp) bind(c, name='fflush') result(stat)
      import :: c_int, c_ptr
      type(c_ptr), value :: fp
      integer(c_int) :: stat
    end function c_fflush

    function c_fclose(fp) bind(c, name='fclose') result(stat)
      import :: c_int, c_ptr
      type(c_ptr), value :: fp
      integer(c_int) :: stat
    end function c_fclose
  end interface

contains

  !> Open path for writing: mode 'w' (replace) or 'a' (append).
  subroutine cf_open(f, path, mode, err)
    type(checked_file_t), intent(out) :: f
    character(len=*), intent(in) :: path, mode
    type(error_t), allocatable, intent(out) :: err
    f%path = path
    f%fp = c_fopen(path//c_null_char, mode//c_null_char)
    if (.not. c_associated(f%fp)) call fatal_error(err, 'cannot open '//path//' for writing')
  end subroutine cf_open

  !> Write text as it is (lines end with new_line('a') given by the caller).
  subroutine cf_write_text(f, text, err)
    type(checked_file_t), intent(inout) :: f
    character(len=*), intent(in) :: text
    type(error_t), allocatable, intent(out) :: err
    call put(f, text, len(text), err)
  end subroutine cf_write_text

  subroutine cf_write_bytes(f, bytes, err)
    type(checked_file_t), intent(inout) :: f
    character(kind=c_char), intent(in) :: bytes(:)
    type(error_t), allocatable, intent(out) :: err
    call put(f, bytes, size(bytes), err)
  end subroutine cf_write_bytes

  subroutine put(f, buf, n, err)
    type(checked_file_t), intent(inout) :: f
    character(kind=c_char), intent(in) :: buf(*)
    integer, intent(in) :: n
    type(error_t), allocatable, intent(out) :: err
    if (n == 0) return
    if (c_fwrite(buf, 1_c_size_t, int(n, c_size_t), f%fp) /= int(n, c_size_t)) &
      call fatal_error(err, 'cannot write '//f%path//full)
  end subroutine put

  !> Hand what is written to the system (a process killed later loses none of it).
  subroutine cf_flush(f, err)
    type(checked_file_t), intent(inout) :: f
    type(error_t), allocatable, intent(out) :: err
    if (c_fflush(f%fp) /= 0) call fatal_error(err, 'cannot write '//f%path//full)
  end subroutine cf_flush

  subroutine cf_close(f, err)
    type(checked_file_t), intent(inout) :: f
    type(error_t), allocatable, intent(out) :: err
    integer(c_int) :: stat
    if (.not. c_associated(f%fp)) return
    stat = c_fclose(f%fp)
    f%fp = c_null_ptr
    if (stat /= 0) call fatal_error(err, 'cannot write '//f%path//full)
  end subroutine cf_close

  !> After an error: close without a word and delete the file.
  subroutine cf_discard(f)
    type(checked_file_t), intent(inout) :: f
    integer(c_int) :: stat
    if (c_associated(f%fp)) stat = c_fclose(f%fp)
    f%fp = c_null_ptr
    if (allocated(f%path)) call delete_file(f%path)
  end subroutine cf_discard

  subroutine write_text_atomic(path, text, err)
    character(len=*), intent(in) :: path, text
    type(error_t), allocatable, intent(out) :: err
    call write_atomic(path, text, len(text), err)
  end subroutine write_text_atomic

  subroutine write_bytes_atomic(path, bytes, err)
    character(len=*), intent(in) :: path
    character(kind=c_char), intent(in) :: bytes(:)
    type(error_t), allocatable, intent(out) :: err
    call write_atomic(path, bytes, size(bytes), err)
  end subroutine write_bytes_atomic

  !> The file path with the content buf(1:n): written to path.part and renamed onto path only
  !> when complete, so a reader never sees a half-written file.
  subroutine write_atomic(path, buf, n, err)
    character(len=*), intent(in) :: path
    character(kind=c_char), intent(in) :: buf(*)
    integer, intent(in) :: n
    type(error_t), allocatable, intent(out) :: err
    type(checked_file_t) :: f
    call cf_open(f, path//'.part', 'w', err)
    if (.not. allocated(err)) call put(f, buf, n, err)
    if (.not. allocated(err)) call cf_close(f, err)
    if (allocated(err)) then
      call cf_discard(f); return
    end if
    if (.not. rename_file(path//'.part', path)) then
      call delete_file(path//'.part')
      call fatal_error(err, 'cannot rename '//path//'.part to '//path)
    end if
  end subroutine write_atomic
end module casca_checked_file
