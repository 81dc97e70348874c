!> Replacing a file atomically: write NAME.part, then rename it onto NAME, so that a reader
!> never sees a half-written result. Fortran 2008 has no rename, so the C library's is used.
module casca_files
  use, intrinsic :: iso_c_binding, only: c_char, c_int, c_null_char
  implicit none
  private
  public :: rename_file, delete_file

  interface
    function c_rename(old, new) bind(c, name='rename') result(stat)
      import :: c_char, c_int
      character(kind=c_char), intent(in) :: old(*), new(*)
      integer(c_int) :: stat
    end function c_rename
  end interface

contains

  !> .true. when old now has the name new
  logical function rename_file(old, new)
    character(len=*), intent(in) :: old, new
    rename_file = c_rename(old//c_null_char, new//c_null_char) == 0
  end function rename_file

  !> Remove a file if it exists (a failed .part).
  subroutine delete_file(path)
    character(len=*), intent(in) :: path
    integer :: u, ios
    open (newunit=u, file=path, status='old', iostat=ios)
    if (ios == 0) close (u, status='delete', iostat=ios)
  end subroutine delete_file
end module casca_files
