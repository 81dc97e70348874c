!> A request to stop the run (SIGTERM, SIGINT or SIGUSR1: a batch system's time limit, Ctrl-C,
!> or `kill -USR1` sent to mpirun, which kills its ranks about a second after a SIGTERM but
!> passes SIGUSR1 on): caught by sysinfo.c and seen by the time loop at a step's end, where the
!> state is whole and a checkpoint of it can be written; statics also looks between Newton
!> solves within a load step, which it then abandons for the last converged one.
module casca_stop_request
  use, intrinsic :: iso_c_binding, only: c_int, c_char, c_null_char
  use casca_mpi, only: max_all
  implicit none
  private
  public :: catch_stop_signals, stop_requested, signal_name

  interface
    subroutine c_catch_stop() bind(c, name='casca_catch_stop')
    end subroutine c_catch_stop

    function c_stop_signal() bind(c, name='casca_stop_signal') result(sig)
      import :: c_int
      integer(c_int) :: sig
    end function c_stop_signal

    subroutine c_signal_name(sig, name) bind(c, name='casca_signal_name')
      import :: c_int, c_char
      integer(c_int), value :: sig
      character(kind=c_char) :: name(16)
    end subroutine c_signal_name
  end interface

contains

  !> From here on, a stop signal is kept for stop_requested instead of ending the process
  subroutine catch_stop_signals()
    call c_catch_stop()
  end subroutine catch_stop_signals

  !> The signal caught on any rank (0: none); collective, so that every rank stops at the
  !> same step
  integer function stop_requested() result(sig)
    sig = c_stop_signal()
    call max_all(sig)
  end function stop_requested

  !> 'SIGTERM' for SIGTERM's number, as a user knows it (the C library's macros: the numbers
  !> differ between systems)
  function signal_name(sig) result(name)
    integer, intent(in) :: sig
    character(len=:), allocatable :: name
    character(kind=c_char) :: buf(16)
    integer :: n
    call c_signal_name(int(sig, c_int), buf)
    n = findloc(buf, c_null_char, dim=1) - 1
    allocate (character(len=n) :: name)
    name = transfer(buf(1:n), name)
  end function signal_name
end module casca_stop_request
