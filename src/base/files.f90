!> Replacing a file atomically: write NAME.part, then rename it onto NAME, so that a reader
!> never sees a half-written result; making folders. Fortran 2008 has neither rename nor mkdir,
!> so the C library's are used (never a shell: a name is then only a name).
module casca_files
  use, intrinsic :: iso_c_binding, only: c_char, c_int, c_null_char, c_long, c_long_long
  use, intrinsic :: iso_fortran_env, only: int64
  implicit none
  private
  public :: rename_file, delete_file, make_dir, is_dir, cut_to_last_line, ends_in_newline, &
            file_kind, physical_memory, close_complete, folder_of
  !> kinds of file_kind
  integer, parameter, public :: kind_missing = 0, kind_regular = 1, kind_folder = 2, kind_special = 3

  interface
    function c_rename(old, new) bind(c, name='rename') result(stat)
      import :: c_char, c_int
      character(kind=c_char), intent(in) :: old(*), new(*)
      integer(c_int) :: stat
    end function c_rename

    function c_mkdir(path, mode) bind(c, name='mkdir') result(stat)
      import :: c_char, c_int
      character(kind=c_char), intent(in) :: path(*)
      integer(c_int), value :: mode   ! mode_t: unsigned int on Linux
      integer(c_int) :: stat
    end function c_mkdir

    function c_truncate(path, length) bind(c, name='truncate') result(stat)
      import :: c_char, c_int, c_long
      character(kind=c_char), intent(in) :: path(*)
      integer(c_long), value :: length   ! off_t: 64 bits on Linux x86_64
      integer(c_int) :: stat
    end function c_truncate

    function c_file_kind(path, size) bind(c, name='casca_file_kind') result(kind)   ! sysinfo.c
      import :: c_char, c_int, c_long_long
      character(kind=c_char), intent(in) :: path(*)
      integer(c_long_long), intent(out) :: size
      integer(c_int) :: kind
    end function c_file_kind

    function c_physical_memory() bind(c, name='casca_physical_memory') result(bytes)
      import :: c_long_long
      integer(c_long_long) :: bytes
    end function c_physical_memory
  end interface

contains

  !> .true. when old now has the name new
  logical function rename_file(old, new)
    character(len=*), intent(in) :: old, new
    rename_file = c_rename(old//c_null_char, new//c_null_char) == 0
  end function rename_file

  !> Make the folder path and its missing parents (as mkdir -p); .true. when it is a folder now.
  logical function make_dir(path)
    character(len=*), intent(in) :: path
    integer :: i, stat
    do i = 2, len(path)   ! every parent, from the top: "a/b/c" makes a, a/b, then a/b/c
      if (path(i:i) == '/' .and. path(i - 1:i - 1) /= '/') then
        if (.not. is_dir(path(1:i - 1))) stat = c_mkdir(path(1:i - 1)//c_null_char, int(o'777', c_int))
      end if
    end do
    if (.not. is_dir(path)) stat = c_mkdir(path//c_null_char, int(o'777', c_int))
    make_dir = is_dir(path)
  end function make_dir

  !> .true. when path names a folder (a file "path/." exists only then)
  logical function is_dir(path)
    character(len=*), intent(in) :: path
    inquire (file=path//'/.', exist=is_dir)
  end function is_dir

  !> Cut a text file after its last newline: a line half-written when the disk filled up is
  !> not left looking like a row.
  subroutine cut_to_last_line(path)
    character(len=*), intent(in) :: path
    character(len=:), allocatable :: text
    integer :: u, ios, n, stat
    if (ends_in_newline(path)) return
    open (newunit=u, file=path, access='stream', form='unformatted', status='old', &
          action='read', iostat=ios)
    if (ios /= 0) return
    inquire (unit=u, size=n)
    allocate (character(len=max(n, 0)) :: text)
    if (n > 0) read (u, iostat=ios) text
    close (u)
    if (ios /= 0 .or. n <= 0) return
    stat = c_truncate(path//c_null_char, int(index(text, new_line('a'), back=.true.), c_long))
  end subroutine cut_to_last_line

  !> Whether the text file path ends with a newline, as every line a writer finished does
  !> (also for an empty file; .true. where it cannot be read: nothing to cut)
  logical function ends_in_newline(path)
    character(len=*), intent(in) :: path
    character :: last
    integer :: u, ios, n
    ends_in_newline = .true.
    open (newunit=u, file=path, access='stream', form='unformatted', status='old', &
          action='read', iostat=ios)
    if (ios /= 0) return
    inquire (unit=u, size=n)
    if (n > 0) then
      read (u, pos=n, iostat=ios) last
      if (ios == 0) ends_in_newline = last == new_line('a')
    end if
    close (u)
  end function ends_in_newline

  !> kind_missing, kind_regular, kind_folder or kind_special (FIFO, device, socket) of the
  !> file path, and its size in bytes (64 bits)
  integer function file_kind(path, size)
    character(len=*), intent(in) :: path
    integer(int64), intent(out), optional :: size
    integer(c_long_long) :: bytes
    file_kind = c_file_kind(path//c_null_char, bytes)
    if (present(size)) size = bytes
  end function file_kind

  !> Physical memory of the machine in bytes (0 if unknown)
  integer(int64) function physical_memory()
    physical_memory = c_physical_memory()
  end function physical_memory

  !> Close the stream unit u, open on path, and tell whether path holds all that was written:
  !> gfortran reports neither in WRITE nor in CLOSE that buffered data met a full disk.
  logical function close_complete(u, path)
    integer, intent(in) :: u
    character(len=*), intent(in) :: path
    integer(int64) :: pos, size
    integer :: ios
    inquire (unit=u, pos=pos)
    close (u, iostat=ios)
    close_complete = ios == 0 .and. file_kind(path, size) == kind_regular .and. size == pos - 1
  end function close_complete

  !> The folder that holds path: '.' for a bare name, '/' for a file at the root
  pure function folder_of(path) result(folder)
    character(len=*), intent(in) :: path
    character(len=:), allocatable :: folder
    integer :: k
    k = index(path, '/', back=.true.)
    if (k == 0) then
      folder = '.'
    else if (k == 1) then
      folder = '/'
    else
      folder = path(1:k - 1)
    end if
  end function folder_of

  !> Remove a file if it exists (a failed .part).
  subroutine delete_file(path)
    character(len=*), intent(in) :: path
    integer :: u, ios
    open (newunit=u, file=path, status='old', iostat=ios)
    if (ios == 0) close (u, status='delete', iostat=ios)
  end subroutine delete_file
end module casca_files
