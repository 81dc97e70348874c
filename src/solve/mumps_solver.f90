!> Sparse symmetric (indefinite) solver: MUMPS on one group of ranks (casca_mpi's
!> group_handle; all ranks when there is one group), with the matrix distributed over the
!> group as assembled entries (ICNTL(18) = 3) and right-hand side and solution on the group's
!> host (its first rank). The analysis is kept while the sparsity pattern does not change;
!> each Newton iteration only refactorises (JOB = 2) and solves (JOB = 3). With single, a
!> single-precision instance (SMUMPS, same settings) analyses, factorises and solves instead.
module casca_mumps_solver
  use casca_kinds, only: dp
  use casca_error, only: error_t, fatal_error
  use casca_mpi, only: group_handle, comm_handle
  implicit none
  private
  public :: sparse_solver_t, mumps_version

  include 'dmumps_struc.h'
  include 'smumps_struc.h'

  interface   ! MUMPS ships no module: the one entry point, declared here
    subroutine dmumps(id)
      import :: dmumps_struc
      type(dmumps_struc), intent(inout) :: id
    end subroutine dmumps
    subroutine smumps(id)
      import :: smumps_struc
      type(smumps_struc), intent(inout) :: id
    end subroutine smumps
  end interface

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
  subroutine solver_init(self, ngroups)
    class(sparse_solver_t), intent(inout) :: self
    integer, intent(in) :: ngroups
    if (self%started .and. self%ngroups == ngroups) return
    call self%finish()
    self%ngroups = ngroups
    self%id%comm = group_handle(ngroups)
    self%id%sym = 2    ! symmetric, possibly indefinite (saddle points of contact)
    self%id%par = 1    ! the host works too
    self%id%job = -1
    call dmumps(self%id)
    ! ICNTL only after JOB = -1
    self%id%icntl(1) = -1; self%id%icntl(2) = -1; self%id%icntl(3) = -1; self%id%icntl(4) = 0
    self%id%icntl(18) = 3             ! distributed assembled matrix
    self%id%icntl(7) = self%ordering
    self%id%icntl(14) = 40            ! workspace margin (percent)
    self%id%icntl(13) = 1             ! no ScaLAPACK root: cheaper for our small fronts
    self%id%icntl(24) = 0
    if (self%single) then   ! the same settings; the double instance then holds no matrix
      self%sid%comm = self%id%comm; self%sid%sym = self%id%sym; self%sid%par = self%id%par
      self%sid%job = -1
      call smumps(self%sid)
      self%sid%icntl = self%id%icntl
    end if
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
      call analyse_single(self%sid)
      self%id%infog(1:2) = self%sid%infog(1:2)   ! (check reads id)
    else
      if (associated(self%id%irn_loc)) deallocate (self%id%irn_loc, self%id%jcn_loc, self%id%a_loc)
      self%id%n = n
      self%id%nnz_loc = size(irn, kind=8)
      allocate (self%id%irn_loc(size(irn)), self%id%jcn_loc(size(irn)), self%id%a_loc(size(irn)))
      self%id%irn_loc = irn
      self%id%jcn_loc = jcn
      self%id%a_loc = 0
      if (associated(self%id%perm_in)) deallocate (self%id%perm_in)
      self%id%icntl(7) = self%ordering
      if (self%ordering == 1 .and. self%host()) then
        allocate (self%id%perm_in(n))
        self%id%perm_in = perm
      end if
      self%id%job = 1
      call dmumps(self%id)
    end if
    call check(self, 'analysis', err)
    self%analysed = .not. allocated(err)
    self%factored = .false.
  contains
    subroutine analyse_single(sid)   ! the same, on the single-precision instance
      type(smumps_struc), intent(inout) :: sid
      if (associated(sid%irn_loc)) deallocate (sid%irn_loc, sid%jcn_loc, sid%a_loc)
      sid%n = n
      sid%nnz_loc = size(irn, kind=8)
      allocate (sid%irn_loc(size(irn)), sid%jcn_loc(size(irn)), sid%a_loc(size(irn)))
      sid%irn_loc = irn
      sid%jcn_loc = jcn
      sid%a_loc = 0
      if (associated(sid%perm_in)) deallocate (sid%perm_in)
      sid%icntl(7) = self%ordering
      if (self%ordering == 1 .and. self%host()) then
        allocate (sid%perm_in(n))
        sid%perm_in = perm
      end if
      sid%job = 1
      call smumps(sid)
    end subroutine analyse_single
  end subroutine solver_analyse

  !> Numerical factorisation of this rank's values (same order as the analysed pattern).
  subroutine solver_factorise(self, a, err)
    class(sparse_solver_t), intent(inout) :: self
    real(dp), intent(in) :: a(:)
    type(error_t), allocatable, intent(out) :: err
    integer :: attempt
    if (self%single) then   ! (as below, in single precision)
      self%sid%a_loc = real(a, kind(self%sid%a_loc))
      do attempt = 1, 4
        self%sid%job = 2
        call smumps(self%sid)
        if (self%sid%infog(1) /= -8 .and. self%sid%infog(1) /= -9) exit
        self%sid%icntl(14) = 2*self%sid%icntl(14)
      end do
      self%id%infog(1:2) = self%sid%infog(1:2); self%id%infog(12) = self%sid%infog(12)
    else
      self%id%a_loc = a
      do attempt = 1, 4
        self%id%job = 2
        call dmumps(self%id)
        ! -8, -9: workspace too small (more pivoting than the analysis forecast): grow and retry
        if (self%id%infog(1) /= -8 .and. self%id%infog(1) /= -9) exit
        self%id%icntl(14) = 2*self%id%icntl(14)
      end do
    end if
    call check(self, 'factorisation', err)
    self%factored = .not. allocated(err)
  end subroutine solver_factorise

  !> X = K^-1 B for m right-hand sides at once (B, X: (n, m)); B is needed on the host only,
  !> X is returned on the host (zero elsewhere).
  subroutine solver_solve(self, b, x, err)
    class(sparse_solver_t), intent(inout) :: self
    real(dp), intent(in) :: b(:, :)
    real(dp), intent(out) :: x(:, :)
    type(error_t), allocatable, intent(out) :: err
    integer :: n, m
    n = size(b, 1); m = size(b, 2)
    if (self%single) then
      if (self%host()) then
        if (associated(self%sid%rhs)) then
          if (size(self%sid%rhs) /= n*m) deallocate (self%sid%rhs)
        end if
        if (.not. associated(self%sid%rhs)) allocate (self%sid%rhs(n*m))
        self%sid%rhs = real(reshape(b, [n*m]), kind(self%sid%rhs))
      end if
      self%sid%nrhs = m; self%sid%lrhs = n
      self%sid%job = 3
      call smumps(self%sid)
      self%id%infog(1:2) = self%sid%infog(1:2)
      call check(self, 'solution', err)
      x = 0
      if (self%host() .and. .not. allocated(err)) x = reshape(real(self%sid%rhs, dp), [n, m])
      return
    end if
    if (self%host()) then
      if (associated(self%id%rhs)) then
        if (size(self%id%rhs) /= n*m) deallocate (self%id%rhs)
      end if
      if (.not. associated(self%id%rhs)) allocate (self%id%rhs(n*m))
      self%id%rhs = reshape(b, [n*m])
    end if
    self%id%nrhs = m; self%id%lrhs = n
    self%id%job = 3
    call dmumps(self%id)
    call check(self, 'solution', err)
    x = 0
    if (self%host() .and. .not. allocated(err)) x = reshape(self%id%rhs, [n, m])
  end subroutine solver_solve

  !> Negative pivots of the last factorisation (the inertia of a saddle-point matrix).
  integer function solver_negative_pivots(self)
    class(sparse_solver_t), intent(in) :: self
    solver_negative_pivots = self%id%infog(12)
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

  !> Free the instance (JOB = -2; collective over its ranks). Elemental, so that the driver
  !> ends all its solvers with one call.
  impure elemental subroutine solver_finish(self)
    class(sparse_solver_t), intent(inout) :: self
    if (.not. self%started) return
    if (associated(self%id%irn_loc)) deallocate (self%id%irn_loc, self%id%jcn_loc, self%id%a_loc)
    if (associated(self%id%rhs)) deallocate (self%id%rhs)
    if (associated(self%id%perm_in)) deallocate (self%id%perm_in)
    self%id%job = -2
    call dmumps(self%id)
    if (self%single) then
      if (associated(self%sid%irn_loc)) deallocate (self%sid%irn_loc, self%sid%jcn_loc, self%sid%a_loc)
      if (associated(self%sid%rhs)) deallocate (self%sid%rhs)
      if (associated(self%sid%perm_in)) deallocate (self%sid%perm_in)
      self%sid%job = -2
      call smumps(self%sid)
    end if
    self%started = .false.; self%analysed = .false.; self%factored = .false.
  end subroutine solver_finish

  subroutine check(self, what, err)
    class(sparse_solver_t), intent(in) :: self
    character(len=*), intent(in) :: what
    type(error_t), allocatable, intent(out) :: err
    character(len=160) :: msg
    if (self%id%infog(1) >= 0) return
    select case (self%id%infog(1))
    case (-10)
      msg = 'the tangent matrix is singular (a body is not restrained or a load is unstable)'
    case default
      write (msg, '(a,i0,a,i0)') 'MUMPS error INFOG(1) = ', self%id%infog(1), &
        ', INFOG(2) = ', self%id%infog(2)
    end select
    call fatal_error(err, 'linear solver '//what//': '//trim(msg))
  end subroutine check
end module casca_mumps_solver
