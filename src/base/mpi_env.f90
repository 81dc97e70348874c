!> The only place MPI is set up: rank, size, and the few collectives casca uses.
module casca_mpi
  use mpi_f08, only: MPI_Comm, MPI_COMM_WORLD, MPI_DOUBLE_PRECISION, MPI_INTEGER, MPI_SUM, &
                     mpi_init, mpi_finalize, mpi_comm_rank, &
                     mpi_comm_size, mpi_initialized, mpi_finalized, mpi_wtime, mpi_allreduce, &
                     mpi_bcast
  use casca_kinds, only: dp
  implicit none
  private
  public :: mpi_start, mpi_stop, comm, comm_handle, my_rank, n_ranks, is_root, wall_time
  public :: sum_all, bcast_real, bcast_int

  type(MPI_Comm), protected :: comm
  integer, protected :: my_rank = 0
  integer, protected :: n_ranks = 1

  interface sum_all
    module procedure sum_all_r1, sum_all_r0
  end interface sum_all

  interface bcast_real
    module procedure bcast_r1, bcast_r0
  end interface bcast_real

  interface bcast_int
    module procedure bcast_i1, bcast_i0
  end interface bcast_int

contains

  subroutine mpi_start()
    integer :: ierr
    logical :: started
    call mpi_initialized(started, ierr)
    if (.not. started) call mpi_init(ierr)
    comm = MPI_COMM_WORLD
    call mpi_comm_rank(comm, my_rank, ierr)
    call mpi_comm_size(comm, n_ranks, ierr)
  end subroutine mpi_start

  subroutine mpi_stop()
    integer :: ierr
    logical :: done
    call mpi_finalized(done, ierr)
    if (.not. done) call mpi_finalize(ierr)
  end subroutine mpi_stop

  !> The communicator as the integer handle of the old interface (for MUMPS).
  integer function comm_handle()
    comm_handle = comm%mpi_val
  end function comm_handle

  logical function is_root()
    is_root = my_rank == 0
  end function is_root

  real(dp) function wall_time()
    wall_time = mpi_wtime()
  end function wall_time

  subroutine sum_all_r1(x)
    real(dp), intent(inout) :: x(:)
    real(dp), allocatable :: y(:)
    integer :: ierr
    if (n_ranks == 1) return
    allocate (y(size(x)))
    call mpi_allreduce(x, y, size(x), MPI_DOUBLE_PRECISION, MPI_SUM, comm, ierr)
    x = y
  end subroutine sum_all_r1

  subroutine sum_all_r0(x)
    real(dp), intent(inout) :: x
    real(dp) :: y(1)
    integer :: ierr
    if (n_ranks == 1) return
    call mpi_allreduce([x], y, 1, MPI_DOUBLE_PRECISION, MPI_SUM, comm, ierr)
    x = y(1)
  end subroutine sum_all_r0



  !> Broadcast from rank 0.
  subroutine bcast_r1(x)
    real(dp), intent(inout) :: x(:)
    integer :: ierr
    if (n_ranks > 1) call mpi_bcast(x, size(x), MPI_DOUBLE_PRECISION, 0, comm, ierr)
  end subroutine bcast_r1

  subroutine bcast_r0(x)
    real(dp), intent(inout) :: x
    real(dp) :: y(1)
    integer :: ierr
    if (n_ranks == 1) return
    y(1) = x
    call mpi_bcast(y, 1, MPI_DOUBLE_PRECISION, 0, comm, ierr)
    x = y(1)
  end subroutine bcast_r0

  subroutine bcast_i1(x)
    integer, intent(inout) :: x(:)
    integer :: ierr
    if (n_ranks > 1) call mpi_bcast(x, size(x), MPI_INTEGER, 0, comm, ierr)
  end subroutine bcast_i1

  subroutine bcast_i0(x)
    integer, intent(inout) :: x
    integer :: y(1)
    if (n_ranks == 1) return
    y(1) = x
    call bcast_i1(y)
    x = y(1)
  end subroutine bcast_i0
end module casca_mpi
