!> Tiny assertion helpers shared by the Fortran unit tests: every check prints its figure
!> and its bound; the program ends with the "N passed, N failed" line ctest logs show.
module casca_check
  use casca_kinds, only: dp
  use casca_mpi, only: is_root
  implicit none
  private
  public :: check_le, check_close, check_true, check_summary

  integer :: npass = 0, nfail = 0

contains

  !> value <= bound
  subroutine check_le(name, value, bound)
    character(len=*), intent(in) :: name
    real(dp), intent(in) :: value, bound
    call record(name, value <= bound, value, bound, '<=')
  end subroutine check_le

  !> |value - expected| <= rtol |expected|
  subroutine check_close(name, value, expected, rtol)
    character(len=*), intent(in) :: name
    real(dp), intent(in) :: value, expected, rtol
    character(len=32) :: s
    write (s, '(es10.3)') rtol
    call record(name, abs(value - expected) <= rtol*abs(expected), value, expected, &
                '~ (rtol '//trim(adjustl(s))//')')
  end subroutine check_close

  subroutine check_true(name, ok)
    character(len=*), intent(in) :: name
    logical, intent(in) :: ok
    if (ok) then
      npass = npass + 1; if (is_root()) print '(a,a)', 'PASS ', name
    else
      nfail = nfail + 1; if (is_root()) print '(a,a)', 'FAIL ', name
    end if
  end subroutine check_true

  subroutine record(name, ok, value, ref, rel)
    character(len=*), intent(in) :: name, rel
    logical, intent(in) :: ok
    real(dp), intent(in) :: value, ref
    if (ok) then
      npass = npass + 1
      if (is_root()) print '(a,a,a,es14.6,1x,a,1x,es14.6)', 'PASS ', name, ': ', value, rel, ref
    else
      nfail = nfail + 1
      if (is_root()) print '(a,a,a,es14.6,1x,a,1x,es14.6)', 'FAIL ', name, ': ', value, rel, ref
    end if
  end subroutine record

  !> Print the closing line and stop with a non-zero code if anything failed.
  subroutine check_summary()
    if (is_root()) print '(i0,a,i0,a)', npass, ' passed, ', nfail, ' failed'
    if (nfail > 0) error stop 1
  end subroutine check_summary
end module casca_check
