!> Errors are passed up as an allocatable error_t (fpm's convention): a library routine never
!> stops the program; the driver decides what to print and which exit code to use.
module casca_error
  implicit none
  private
  public :: error_t, fatal_error

  type :: error_t
    character(len=:), allocatable :: message
  end type error_t

contains

  !> Allocate err with msg (the routine that detects the problem calls this and returns).
  pure subroutine fatal_error(err, msg)
    type(error_t), allocatable, intent(out) :: err
    character(len=*), intent(in) :: msg
    allocate (err)
    err%message = msg
  end subroutine fatal_error
end module casca_error
