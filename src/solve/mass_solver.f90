!> The consistent mass M = m (x) I3 over the vector parameters (Y, G) of every node: each
!> component x, y, z is a sparse symmetric positive definite system of its own (restrained
!> parameters left out; A carries no mass), factorised once per run by MUMPS on each rank
!> alone, for the contact correction, which is replicated like the contact itself.
!> Components with the same restraints (the usual case) share one factorisation, so that
!> the right-hand sides of all three go to MUMPS in one call. The contact correction's
!> right-hand sides have a few nonzeros each (the nodes of a constraint), so M^-1 is applied
!> through cached columns M^-1 e_i of the equations touched: a contact patch that stays in
!> place costs no solve after its first step (three spheres: the correction's time from
!> 13 s to 2.9 s of a 58 s run).
module casca_mass_solver
  use casca_kinds, only: dp
  use casca_error, only: error_t
  use casca_model, only: model_t, dof
  use casca_mumps_solver, only: sparse_solver_t
  use casca_mpi, only: n_ranks
  implicit none
  private
  public :: mass_solver_t, mass_setup

  !> Columns M^-1 e_i of one system, for the equations i met so far (slot(i) > 0)
  type :: column_cache_t
    integer, allocatable :: slot(:)
    real(dp), allocatable :: col(:, :)
    integer :: n = 0
  end type column_cache_t

  integer, parameter :: cache_bytes = 200*1024*1024   !< a full cache is emptied, not grown

  type :: mass_solver_t
    type(sparse_solver_t) :: m(3)        !< the scalar mass of component c's free parameters
    integer, allocatable :: eq(:)        !< (ndof) equation of each free Y, G parameter in its
                                         !< component's system; 0 restrained, or A
    integer, allocatable :: dofs(:, :)   !< (neq, c) the dof of each equation of component c
    integer :: neq(3) = 0
    integer :: solver_of(3) = [1, 2, 3]  !< components with the same restraints share one
    type(column_cache_t) :: cache(3)     !< per system
  contains
    procedure :: columns => mass_columns
    procedure :: solve => mass_solve
    procedure :: finish => mass_finish
  end type mass_solver_t

contains

  !> Number, assemble and factorise the component systems.
  subroutine mass_setup(model, ms, err)
    type(model_t), intent(in) :: model
    type(mass_solver_t), intent(inout) :: ms
    type(error_t), allocatable, intent(out) :: err
    integer, allocatable :: irn(:), jcn(:), noperm(:), comp_dofs(:)
    real(dp), allocatable :: a(:)
    integer :: c, c2, n, e, p, qq, k, ip, iq
    allocate (ms%eq(model%ndof), ms%dofs(2*model%nnode, 3), noperm(0))
    ms%eq = 0; ms%dofs = 0
    do c = 1, 3
      k = 0
      do n = 1, model%nnode
        do p = 0, 1   ! Y, then G
          if (model%fixed(dof(n, c + 3*p))) cycle
          k = k + 1; ms%eq(dof(n, c + 3*p)) = k; ms%dofs(k, c) = dof(n, c + 3*p)
        end do
      end do
      ms%neq(c) = k
    end do
    do c = 2, 3   ! same restraints as an earlier component: same matrix
      do c2 = 1, c - 1
        comp_dofs = [(dof(n, c), dof(n, c + 3), n=1, model%nnode)]
        if (all(model%fixed(comp_dofs) .eqv. model%fixed(comp_dofs - c + c2))) then
          ms%solver_of(c) = ms%solver_of(c2); exit
        end if
      end do
    end do
    do c = 1, 3
      if (ms%solver_of(c) /= c .or. ms%neq(c) == 0) cycle
      allocate (irn(210*model%nelem), jcn(210*model%nelem), a(210*model%nelem))
      k = 0
      do e = 1, model%nelem
        do qq = 1, 20
          iq = ms%eq(param_dof(e, qq, c))
          if (iq == 0) cycle
          do p = 1, 20
            ip = ms%eq(param_dof(e, p, c))
            if (ip < iq) cycle   ! lower triangle
            k = k + 1; irn(k) = ip; jcn(k) = iq; a(k) = model%emass(p, qq, e)
          end do
        end do
      end do
      ! each rank alone: the correction is replicated like the contact
      call ms%m(c)%analyse(ms%neq(c), irn(1:k), jcn(1:k), noperm, err, n_ranks)
      if (.not. allocated(err)) call ms%m(c)%factorise(a(1:k), err)
      deallocate (irn, jcn, a)
      if (allocated(err)) return
    end do
  contains
    !> the dof of component c of vector parameter p (1..10 Y, 11..20 G) of element e
    pure integer function param_dof(e, p, c)
      integer, intent(in) :: e, p, c
      param_dof = dof(model%conn(1 + mod(p - 1, 10), e), c + 3*((p - 1)/10))
    end function param_dof
  end subroutine mass_setup

  !> x(:, 1:ncol) = m^-1 G for system s, G sparse by columns (ptr(ncol + 1), its equations
  !> idx and values val; a few nonzeros each): x = sum val M^-1 e_idx, the columns missing
  !> from the cache solved at once and kept. x is the caller's, grown when too small (never
  !> shrunk): a contact patch that stays costs no allocation.
  subroutine mass_columns(self, s, ptr, idx, val, x, err)
    class(mass_solver_t), intent(inout) :: self
    integer, intent(in) :: s, ptr(:), idx(:)
    real(dp), intent(in) :: val(:)
    real(dp), allocatable, intent(inout) :: x(:, :)
    type(error_t), allocatable, intent(out) :: err
    integer :: n, j, k, ncol
    n = self%neq(s); ncol = size(ptr) - 1
    call cache_columns(self, s, idx, err)
    if (allocated(err)) return
    if (allocated(x)) then
      if (size(x, 1) /= n .or. size(x, 2) < ncol) deallocate (x)
    end if
    if (.not. allocated(x)) allocate (x(n, ncol))
    associate (c => self%cache(s))
      do j = 1, ncol
        x(:, j) = 0
        do k = ptr(j), ptr(j + 1) - 1
          x(:, j) = x(:, j) + val(k)*c%col(:, c%slot(idx(k)))
        end do
      end do
    end associate
  end subroutine mass_columns

  !> a = M^-1 f on the free Y, G parameters (0 on the others): the acceleration a dense load
  !> gives (the start's; once per run, so no cache)
  subroutine mass_solve(self, f, a, err)
    class(mass_solver_t), intent(inout) :: self
    real(dp), intent(in) :: f(:)
    real(dp), intent(out) :: a(:)
    type(error_t), allocatable, intent(out) :: err
    real(dp), allocatable :: b(:, :), x(:, :)
    integer :: c, n
    a = 0
    do c = 1, 3
      n = self%neq(c)
      if (n == 0) cycle
      b = reshape(f(self%dofs(1:n, c)), [n, 1])
      if (allocated(x)) deallocate (x)
      allocate (x(n, 1))
      call self%m(self%solver_of(c))%solve(b, x, err)
      if (allocated(err)) return
      a(self%dofs(1:n, c)) = x(:, 1)
    end do
  end subroutine mass_solve

  !> Make sure the cache of system s holds M^-1 e_i for every equation i in idx (a full
  !> cache is emptied, not grown: the equations asked for now are solved again)
  subroutine cache_columns(self, s, idx, err)
    class(mass_solver_t), intent(inout) :: self
    integer, intent(in) :: s, idx(:)
    type(error_t), allocatable, intent(out) :: err
    integer, allocatable :: missing(:)
    real(dp), allocatable :: e(:, :), z(:, :)
    integer :: n, k, m, cap
    n = self%neq(s)
    cap = max(64, cache_bytes/(8*max(n, 1)))
    associate (c => self%cache(s))
      if (.not. allocated(c%slot)) then
        allocate (c%slot(n), c%col(n, 0))
        c%slot = 0
      end if
      allocate (missing(size(idx)))
      do
        m = 0
        do k = 1, size(idx)   ! (marked -1 while listed: each equation once)
          if (c%slot(idx(k)) /= 0) cycle
          m = m + 1; missing(m) = idx(k); c%slot(idx(k)) = -1
        end do
        if (c%n + m <= cap) exit
        if (c%n == 0) then   ! more than a full cache's worth at once: hold them all
          cap = m; exit
        end if
        c%slot = 0; c%n = 0   ! full: start again
      end do
      if (m == 0) return
      allocate (e(n, m), z(n, m))
      e = 0
      do k = 1, m
        e(missing(k), k) = 1
      end do
      call self%m(s)%solve(e, z, err)
      if (allocated(err)) then
        c%slot(missing(1:m)) = 0
        return
      end if
      if (size(c%col, 2) < c%n + m) call grow(c%n + m)
      do k = 1, m
        c%n = c%n + 1
        c%slot(missing(k)) = c%n
        c%col(:, c%n) = z(:, k)
      end do
    end associate
  contains
    subroutine grow(need)
      integer, intent(in) :: need
      real(dp), allocatable :: t(:, :)
      allocate (t(n, min(max(2*need, 16), cap)))
      t(:, 1:self%cache(s)%n) = self%cache(s)%col(:, 1:self%cache(s)%n)
      call move_alloc(t, self%cache(s)%col)
    end subroutine grow
  end subroutine cache_columns

  subroutine mass_finish(self)
    class(mass_solver_t), intent(inout) :: self
    integer :: c
    do c = 1, 3
      call self%m(c)%finish()
    end do
  end subroutine mass_finish
end module casca_mass_solver
