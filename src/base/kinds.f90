!> Working precision and a few constants shared by every module.
module casca_kinds
  use, intrinsic :: iso_fortran_env, only: real64, int32, int64
  implicit none
  private
  public :: dp, i4, i8, pi

  integer, parameter :: dp = real64
  integer, parameter :: i4 = int32
  integer, parameter :: i8 = int64
  real(dp), parameter :: pi = 3.141592653589793238462643383279502884_dp
end module casca_kinds
