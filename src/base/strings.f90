!> Numbers as text for messages (one home for what every module that writes messages needs).
module casca_strings
  use, intrinsic :: iso_fortran_env, only: int32, int64, real64
  implicit none
  private
  public :: itoa, rtoa, vtoa, ftoa, count_of, as_word

  !> n as its shortest decimal text (default and 64-bit integers, e.g. HDF5's hsize_t)
  interface itoa
    module procedure itoa_i32, itoa_i64
  end interface itoa

contains

  pure function itoa_i32(n) result(s)
    integer(int32), intent(in) :: n
    character(len=:), allocatable :: s
    s = itoa_i64(int(n, int64))
  end function itoa_i32

  pure function itoa_i64(n) result(s)
    integer(int64), intent(in) :: n
    character(len=:), allocatable :: s
    character(len=24) :: b
    write (b, '(i0)') n
    s = trim(b)
  end function itoa_i64

  !> x in scientific notation with 5 significant digits, e.g. 2.4190E+04, 1.0000E+300
  pure function rtoa(x) result(s)
    real(real64), intent(in) :: x
    character(len=:), allocatable :: s
    character(len=24) :: b
    integer :: k
    ! (es12.4 drops the E of a 3-digit exponent, 1.0000+300: 3 digits, the first 0 dropped)
    write (b, '(es13.4e3)') x
    s = trim(adjustl(b))
    k = index(s, 'E')
    if (k > 0) then
      if (s(k + 2:k + 2) == '0') s = s(1:k + 1)//s(k + 3:)
    end if
  end function rtoa

  !> (x, y, z) of a point, each as rtoa
  pure function vtoa(x) result(s)
    real(real64), intent(in) :: x(3)
    character(len=:), allocatable :: s
    s = '('//rtoa(x(1))//', '//rtoa(x(2))//', '//rtoa(x(3))//')'
  end function vtoa

  !> x with 3 decimals and a leading zero, e.g. 3.780, 0.125, -0.004 (percentages); beyond
  !> 1e15 (or not a number) as rtoa
  pure function ftoa(x) result(s)
    real(real64), intent(in) :: x
    character(len=:), allocatable :: s
    character(len=24) :: b
    if (.not. abs(x) < 1e15_real64) then
      s = rtoa(x); return
    end if
    write (b, '(f0.3)') x
    s = trim(adjustl(b))
    if (s(1:1) == '.') s = '0'//s
    if (s(1:2) == '-.') s = '-0'//s(2:)
  end function ftoa

  !> n and the noun in the number n asks for: count_of(1, 'body', 'bodies') is '1 body',
  !> count_of(3, 'body', 'bodies') is '3 bodies' (0 takes the plural)
  pure function count_of(n, one, many) result(s)
    integer, intent(in) :: n
    character(len=*), intent(in) :: one, many
    character(len=:), allocatable :: s
    if (n == 1) then
      s = itoa_i32(n)//' '//one
    else
      s = itoa_i32(n)//' '//many
    end if
  end function count_of
  !> name with every character but letters, digits and '_' made '_' (the history's column
  !> names: one word each, as numpy's genfromtxt(names=True) keeps them)
  pure function as_word(name) result(w)
    character(len=*), intent(in) :: name
    character(len=:), allocatable :: w
    integer :: i
    w = trim(name)
    do i = 1, len(w)
      if (verify(w(i:i), 'abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_') /= 0) &
        w(i:i) = '_'
    end do
  end function as_word
end module casca_strings
