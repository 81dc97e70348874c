!> Wall time spent in each part of a run, for the summary a run prints and for benchmarks.
module casca_timers
  use casca_kinds, only: dp
  use casca_mpi, only: wall_time
  implicit none
  private
  public :: timer_start, timer_stop, timer_report, seconds, t_assembly, t_contact, t_analysis, &
            t_factor, t_solve, t_account, t_output, ntimers

  integer, parameter :: t_assembly = 1, t_contact = 2, t_analysis = 3, t_factor = 4, &
                        t_solve = 5, t_account = 6, t_output = 7, ntimers = 7
  character(len=*), parameter :: names(ntimers) = [character(len=13) :: 'elements', &
    'contact', 'analysis', 'factorisation', 'solution', 'accounting', 'output']
  real(dp) :: total(ntimers) = 0, started(ntimers) = 0
  integer :: calls(ntimers) = 0

contains

  subroutine timer_start(i)
    integer, intent(in) :: i
    started(i) = wall_time()
    calls(i) = calls(i) + 1
  end subroutine timer_start

  subroutine timer_stop(i)
    integer, intent(in) :: i
    total(i) = total(i) + wall_time() - started(i)
  end subroutine timer_stop

  !> One line: seconds in each part and the share of the given wall time (with how many
  !> times for the factorisations: what a new step length or contact set costs)
  function timer_report(wall) result(s)
    real(dp), intent(in) :: wall
    character(len=:), allocatable :: s
    character(len=48) :: b
    integer :: i
    s = 'time:'
    do i = 1, ntimers
      write (b, '(a,i0,a)') ' s (', nint(100*total(i)/max(wall, tiny(1._dp))), '%'
      if (i == t_factor) write (b, '(a,a,i0,a)') trim(b), ', ', calls(i), ' times'
      b = trim(b)//')'
      s = s//' '//trim(names(i))//' '//seconds(total(i))//trim(b)
      if (i < ntimers) s = s//','
    end do
  end function timer_report

  !> Seconds with two decimals and a leading zero (f0.2 writes 0.67 as '.67').
  pure function seconds(t) result(s)
    real(dp), intent(in) :: t
    character(len=:), allocatable :: s
    character(len=24) :: b
    write (b, '(f0.2)') t
    s = trim(b)
    if (s(1:1) == '.') s = '0'//s
  end function seconds
end module casca_timers
