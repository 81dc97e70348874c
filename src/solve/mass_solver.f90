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
    procedure :: solve_sparse => mass_solve_sparse
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

  !> x = m^-1 b for system s (b, x: (its neq, nrhs)), b with few nonzero rows: x = sum_i b(i, :) M^-1 e_i,
  !> the columns missing from the cache solved at once and kept
  subroutine mass_solve_sparse(self, s, b, x, err)
    class(mass_solver_t), intent(inout) :: self
    integer, intent(in) :: s
    real(dp), intent(in) :: b(:, :)
    real(dp), intent(out) :: x(:, :)
    type(error_t), allocatable, intent(out) :: err
    integer, allocatable :: rows(:), missing(:)
    real(dp), allocatable :: e(:, :), z(:, :)
    integer :: n, i, j, k, cap
    n = self%neq(s)
    associate (c => self%cache(s))
      if (.not. allocated(c%slot)) then
        allocate (c%slot(n), c%col(n, 0))
        c%slot = 0
      end if
      rows = pack([(i, i=1, n)], any(b /= 0, dim=2))
      missing = pack(rows, c%slot(rows) == 0)
      if (size(missing) > 0) then
        cap = max(64, cache_bytes/(8*max(n, 1)))
        if (c%n + size(missing) > cap) then   ! full: start again
          c%slot = 0; c%n = 0
          missing = rows
        end if
        allocate (e(n, size(missing)), z(n, size(missing)))
        e = 0
        do k = 1, size(missing)
          e(missing(k), k) = 1
        end do
        call self%m(s)%solve(e, z, err)
        if (allocated(err)) return
        if (size(c%col, 2) < c%n + size(missing)) call grow(c%n + size(missing))
        do k = 1, size(missing)
          c%n = c%n + 1
          c%slot(missing(k)) = c%n
          c%col(:, c%n) = z(:, k)
        end do
      end if
      x = 0
      do k = 1, size(rows)
        i = rows(k)
        do j = 1, size(b, 2)
          if (b(i, j) /= 0) x(:, j) = x(:, j) + b(i, j)*c%col(:, c%slot(i))
        end do
      end do
    end associate
  contains
    subroutine grow(need)
      integer, intent(in) :: need
      real(dp), allocatable :: t(:, :)
      allocate (t(n, min(max(2*need, 16), max(64, cache_bytes/(8*max(n, 1))))))
      t(:, 1:self%cache(s)%n) = self%cache(s)%col(:, 1:self%cache(s)%n)
      call move_alloc(t, self%cache(s)%col)
    end subroutine grow
  end subroutine mass_solve_sparse

  subroutine mass_finish(self)
    class(mass_solver_t), intent(inout) :: self
    integer :: c
    do c = 1, 3
      call self%m(c)%finish()
    end do
  end subroutine mass_finish
end module casca_mass_solver
