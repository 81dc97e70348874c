!> The only place MPI is set up: rank, size, the group communicators of the linear solver,
!> and the few collectives casca uses.
module casca_mpi
  use mpi_f08, only: MPI_Comm, MPI_Op, MPI_COMM_WORLD, MPI_DOUBLE_PRECISION, MPI_INTEGER, MPI_SUM, &
                     MPI_MIN, MPI_MAX, MPI_CHARACTER, mpi_init, mpi_finalize, mpi_comm_rank, &
                     mpi_comm_size, mpi_initialized, mpi_finalized, mpi_wtime, mpi_allreduce, &
                     mpi_bcast, mpi_comm_split, mpi_comm_free, mpi_get_library_version, &
                     MPI_MAX_LIBRARY_VERSION_STRING
  use casca_kinds, only: dp
  use casca_error, only: error_t, fatal_error
  implicit none
  private
  public :: mpi_start, mpi_stop, comm, comm_handle, group_handle, my_rank, n_ranks, is_root
  public :: wall_time, sum_all, bcast_real, bcast_int, share_error, max_all, mpi_version

  type(MPI_Comm), protected :: comm
  integer, protected :: my_rank = 0
  integer, protected :: n_ranks = 1
  !> groups(ng): this rank's communicator when the ranks are dealt into ng groups
  type(MPI_Comm), allocatable :: groups(:)
  logical, allocatable :: made(:)

  interface sum_all
    module procedure sum_all_r2, sum_all_r1, sum_all_r0, sum_all_i0
  end interface sum_all

  interface max_all
    module procedure max_all_i0, max_all_r0
  end interface max_all

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
    integer :: ierr, ng
    logical :: done
    call mpi_finalized(done, ierr)
    if (done) return
    if (allocated(made)) then
      do ng = 1, size(made)
        if (made(ng)) call mpi_comm_free(groups(ng), ierr)
      end do
      deallocate (made, groups)
    end if
    call mpi_finalize(ierr)
  end subroutine mpi_stop

  !> The communicator as the integer handle of the old interface (for MUMPS).
  integer function comm_handle()
    comm_handle = comm%mpi_val
  end function comm_handle

  !> Handle of this rank's group when the ranks are dealt round into ng groups (rank r in
  !> group mod(r, ng), ranked as in comm, so world rank g is group g's first). Made on first
  !> use, collectively (every rank must ask for the same ng at the same time), and kept.
  integer function group_handle(ng)
    integer, intent(in) :: ng
    integer :: ierr
    if (ng <= 1 .or. n_ranks == 1) then
      group_handle = comm%mpi_val
      return
    end if
    if (.not. allocated(made)) then
      allocate (groups(n_ranks), made(n_ranks))
      made = .false.
    end if
    if (.not. made(ng)) then
      call mpi_comm_split(comm, mod(my_rank, ng), my_rank, groups(ng), ierr)
      made(ng) = .true.
    end if
    group_handle = groups(ng)%mpi_val
  end function group_handle

  !> Make an error seen by any rank an error on every rank (collective): the one of the
  !> lowest rank that has one, so that rank 0 can print it and no rank waits for the others.
  subroutine share_error(err)
    type(error_t), allocatable, intent(inout) :: err
    integer :: mine(1), first(1), ierr, length(1)
    character(len=:), allocatable :: msg
    if (n_ranks == 1) return
    mine = merge(my_rank, n_ranks, allocated(err))
    call mpi_allreduce(mine, first, 1, MPI_INTEGER, MPI_MIN, comm, ierr)
    if (first(1) == n_ranks) return
    length = 0
    if (my_rank == first(1)) length = len(err%message)
    call mpi_bcast(length, 1, MPI_INTEGER, first(1), comm, ierr)
    allocate (character(len=length(1)) :: msg)
    if (my_rank == first(1)) msg = err%message
    call mpi_bcast(msg, length(1), MPI_CHARACTER, first(1), comm, ierr)
    if (my_rank /= first(1)) call fatal_error(err, msg)
  end subroutine share_error

  !> The MPI library's own version line (casca --version), e.g. "Open MPI v4.1.4, package: ...";
  !> only its first line (MPICH's runs over several). Needs no mpi_start.
  function mpi_version() result(s)
    character(len=:), allocatable :: s
    character(len=MPI_MAX_LIBRARY_VERSION_STRING) :: b
    integer :: n, ierr, k
    b = ''
    call mpi_get_library_version(b, n, ierr)
    if (ierr /= 0) then
      s = 'unknown'
      return
    end if
    n = max(0, min(n, len(b)))
    k = index(b(1:n), new_line('a'))
    if (k > 0) n = k - 1
    s = trim(b(1:n))
  end function mpi_version

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

  subroutine sum_all_r2(x)
    real(dp), intent(inout) :: x(:, :)
    real(dp), allocatable :: y(:, :)
    integer :: ierr
    if (n_ranks == 1) return
    allocate (y(size(x, 1), size(x, 2)))
    call mpi_allreduce(x, y, size(x), MPI_DOUBLE_PRECISION, MPI_SUM, comm, ierr)
    x = y
  end subroutine sum_all_r2

  !> The largest x of all ranks, on every rank (the exit code: all ranks end with the same).
  subroutine max_all_i0(x)
    integer, intent(inout) :: x
    call reduce_i0(x, MPI_MAX)
  end subroutine max_all_i0

  subroutine max_all_r0(x)
    real(dp), intent(inout) :: x
    call reduce_r0(x, MPI_MAX)
  end subroutine max_all_r0

  subroutine sum_all_i0(x)
    integer, intent(inout) :: x
    call reduce_i0(x, MPI_SUM)
  end subroutine sum_all_i0

  subroutine sum_all_r0(x)
    real(dp), intent(inout) :: x
    call reduce_r0(x, MPI_SUM)
  end subroutine sum_all_r0

  !> x combined by op over all ranks, on every rank
  subroutine reduce_i0(x, op)
    integer, intent(inout) :: x
    type(MPI_Op), intent(in) :: op
    integer :: y(1), ierr
    if (n_ranks == 1) return
    call mpi_allreduce([x], y, 1, MPI_INTEGER, op, comm, ierr)
    x = y(1)
  end subroutine reduce_i0

  subroutine reduce_r0(x, op)
    real(dp), intent(inout) :: x
    type(MPI_Op), intent(in) :: op
    real(dp) :: y(1)
    integer :: ierr
    if (n_ranks == 1) return
    call mpi_allreduce([x], y, 1, MPI_DOUBLE_PRECISION, op, comm, ierr)
    x = y(1)
  end subroutine reduce_r0



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
