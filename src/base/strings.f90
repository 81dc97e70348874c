!> Numbers as text for messages (one home for what every module that writes messages needs).
module casca_strings
  implicit none
  private
  public :: itoa

contains

  !> n as its shortest decimal text
  pure function itoa(n) result(s)
    integer, intent(in) :: n
    character(len=:), allocatable :: s
    character(len=16) :: b
    write (b, '(i0)') n
    s = trim(b)
  end function itoa
end module casca_strings
