!> MUMPS's two instance types (it ships no module) and their entry points, declared once.
module casca_mumps_types
  implicit none
  private
  public :: dmumps_struc, dmumps, smumps_struc, smumps

  include 'dmumps_struc.h'
  include 'smumps_struc.h'

  interface
    subroutine dmumps(id)
      import :: dmumps_struc
      type(dmumps_struc), intent(inout) :: id
    end subroutine dmumps
    subroutine smumps(id)
      import :: smumps_struc
      type(smumps_struc), intent(inout) :: id
    end subroutine smumps
  end interface
end module casca_mumps_types

!> The MUMPS calls (mumps_ops.inc) on a double-precision instance ...
module casca_mumps_double
  use casca_mumps_types, only: mumps_struc => dmumps_struc, mumps => dmumps
  include 'mumps_ops.inc'
end module casca_mumps_double

!> ... and the same on a single-precision one.
module casca_mumps_single
  use casca_mumps_types, only: mumps_struc => smumps_struc, mumps => smumps
  include 'mumps_ops.inc'
end module casca_mumps_single

!> Sparse symmetric (indefinite) solver: MUMPS on one group of ranks (casca_mpi's
!> group_handle; all ranks when there is one group), with the matrix distributed over the
!> group as assembled entries (ICNTL(18) = 3) and right-hand side and solution on the group's
!> host (its first rank). The analysis is kept while the sparsity pattern does not change;
!> each Newton iteration only refactorises (JOB = 2) and solves (JOB = 3). With single, a
!> single-precision instance (SMUMPS, same settings) analyses, factorises and solves instead.
module casca_mumps_solver
  use casca_kinds, only: dp
  use casca_error, only: error_t
  use casca_mpi, only: group_handle, comm_handle
  use casca_mumps_types, only: dmumps_struc, smumps_struc, dmumps
  use casca_mumps_double   ! (generic mumps_* names, on either instance)
  use casca_mumps_single
  implicit none
  private
  public :: sparse_solver_t, mumps_version

  type :: sparse_solver_t
    type(dmumps_struc), private :: id
    type(smumps_struc), private :: sid  !< the instance that works when single
    !> factorise and solve in single precision (SMUMPS; &run factor_precision = 'single'):
    !> the matrix and right-hand sides are rounded to single, the solution returned in double.
    !> Set before the first analysis. Newton's residual stays in double, so its iterations
    !> refine the solution (docs/performance.md: the same answers, the same iterations)
    logical :: single = .false.
    logical :: started = .false.
    integer :: ngroups = 1          !< the ranks are dealt into this many groups (one instance each)
    logical :: analysed = .false.
    logical :: factored = .false.   !< holds factors of the analysed pattern
    !> ICNTL(7): 7 = MUMPS chooses (PORD here), 1 = METIS nested dissection given by casca;
    !> equal within 3% on the 720-element sphere (docs/performance.md), so MUMPS chooses
    integer :: ordering = 7
  contains
    procedure :: init => solver_init
    procedure :: analyse => solver_analyse
    procedure :: factorise => solver_factorise
    procedure :: solve => solver_solve
    procedure :: negative_pivots => solver_negative_pivots
    procedure :: host => solver_host
    procedure :: drop_factors => solver_drop_factors
    procedure :: new_pattern => solver_new_pattern
    procedure :: finish => solver_finish
  end type sparse_solver_t

contains

  !> The linked MUMPS library's version, e.g. "5.5.1" (casca --version): MUMPS tells it only
  !> through an instance, so one is started (JOB = -1) and ended (JOB = -2). Collective over
  !> all ranks, like every MUMPS start.
  function mumps_version() result(s)
    character(len=:), allocatable :: s
    type(dmumps_struc) :: id
    id%comm = comm_handle()
    id%sym = 0; id%par = 1
    id%job = -1
    call dmumps(id)
    s = trim(adjustl(id%version_number))
    if (id%info(1) < 0 .or. s == '') s = 'unknown'
    id%icntl(1:3) = -1; id%icntl(4) = 0   ! JOB = -2 would print its banner
    id%job = -2
    call dmumps(id)
  end function mumps_version

  !> Start MUMPS on this rank's group of ngroups (collective over all ranks when it changes).
  !> The double instance starts even when single: it tells host().
  subroutine solver_init(self, ngroups)
    class(sparse_solver_t), intent(inout) :: self
    integer, intent(in) :: ngroups
    if (self%started .and. self%ngroups == ngroups) return
    call self%finish()
    self%ngroups = ngroups
    call mumps_start(self%id, group_handle(ngroups))
    if (self%single) call mumps_start(self%sid, self%id%comm)
    self%started = .true.
  end subroutine solver_init

  !> Symbolic analysis of the pattern irn(k) >= jcn(k) (this rank's entries; duplicates sum)
  !> of this rank's group (ngroups groups; 1 if absent). perm: pivot order (host), used when
  !> ordering = 1.
  subroutine solver_analyse(self, n, irn, jcn, perm, err, ngroups)
    class(sparse_solver_t), intent(inout) :: self
    integer, intent(in) :: n, irn(:), jcn(:), perm(:)
    type(error_t), allocatable, intent(out) :: err
    integer, intent(in), optional :: ngroups
    if (present(ngroups)) then
      call self%init(ngroups)
    else
      call self%init(1)
    end if
    if (self%single) then
      call mumps_analyse(self%sid, n, irn, jcn, perm, self%ordering, err)
    else
      call mumps_analyse(self%id, n, irn, jcn, perm, self%ordering, err)
    end if
    self%analysed = .not. allocated(err)
    self%factored = .false.
  end subroutine solver_analyse

  !> Numerical factorisation of this rank's values (same order as the analysed pattern).
  subroutine solver_factorise(self, a, err)
    class(sparse_solver_t), intent(inout) :: self
    real(dp), intent(in) :: a(:)
    type(error_t), allocatable, intent(out) :: err
    if (self%single) then
      call mumps_factorise(self%sid, a, err)
    else
      call mumps_factorise(self%id, a, err)
    end if
    self%factored = .not. allocated(err)
  end subroutine solver_factorise

  !> X = K^-1 B for m right-hand sides at once (B, X: (n, m)); B is needed on the host only,
  !> X is returned on the host (zero elsewhere).
  subroutine solver_solve(self, b, x, err)
    class(sparse_solver_t), intent(inout) :: self
    real(dp), intent(in) :: b(:, :)
    real(dp), intent(out) :: x(:, :)
    type(error_t), allocatable, intent(out) :: err
    if (self%single) then
      call mumps_solve(self%sid, b, x, err)
    else
      call mumps_solve(self%id, b, x, err)
    end if
  end subroutine solver_solve

  !> Negative pivots of the last factorisation (the inertia of a saddle-point matrix): INFOG(12)
  !> of the instance that works (a solve keeps it).
  integer function solver_negative_pivots(self)
    class(sparse_solver_t), intent(in) :: self
    solver_negative_pivots = merge(self%sid%infog(12), self%id%infog(12), self%single)
  end function solver_negative_pivots

  !> This rank is its group's host (MUMPS's rank 0 in the group): it holds b and x.
  logical function solver_host(self)
    class(sparse_solver_t), intent(in) :: self
    solver_host = self%id%myid == 0
  end function solver_host

  !> The next solve refactorises: used after a checkpoint so that a run restarted from it
  !> takes exactly the path of the run that wrote it.
  subroutine solver_drop_factors(self)
    class(sparse_solver_t), intent(inout) :: self
    self%factored = .false.
  end subroutine solver_drop_factors

  !> The unknowns changed: the next solve analyses again.
  subroutine solver_new_pattern(self)
    class(sparse_solver_t), intent(inout) :: self
    self%analysed = .false.; self%factored = .false.
  end subroutine solver_new_pattern

  !> Free the instances (JOB = -2; collective over its ranks). Elemental, so that the driver
  !> ends all its solvers with one call.
  impure elemental subroutine solver_finish(self)
    class(sparse_solver_t), intent(inout) :: self
    if (.not. self%started) return
    call mumps_finish(self%id)
    if (self%single) call mumps_finish(self%sid)
    self%started = .false.; self%analysed = .false.; self%factored = .false.
  end subroutine solver_finish
end module casca_mumps_solver
