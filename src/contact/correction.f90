!> The velocity after a converged step with contact (persistency, Taylor & Papadopoulos
!> 1993; Laursen & Love 2002 with no restitution), as a projection in the metric of the
!> consistent mass M:
!>     v+ = v + M^-1 C^T nu,   S nu = -C v,   S = C M^-1 C^T,
!> and likewise C a+ = 0 for the acceleration, over every active constraint: each has a
!> compressive multiplier at the end of the step, so it is in contact there, and a contact
!> that opens does so in a later step through its multiplier, never by a velocity it keeps.
!> Without the acceleration's projection a released constraint's force would go on acting
!> through the next step's start acceleration: the trapezoidal rule gains 1/2 p g at every
!> release (two rings: +15% of the energy; with it the energy never rises). The change of
!> momentum is then M (v+ - v) = C^T nu: equal and opposite impulses along n at the two
!> sides of each contact, so the linear and the angular momentum of the free bodies are
!> kept exactly (with a lumped mass only the linear one is), and the kinetic energy drops
!> by 1/2 (C v)^T S^-1 (C v) >= 0: a correction that never adds energy.
module casca_contact_correction
  use casca_kinds, only: dp
  use casca_error, only: error_t, fatal_error
  use casca_model, only: model_t, dof
  use casca_shell_element, only: ndof_node
  use casca_contact, only: contact_t, constraint_t
  use casca_contact_projection, only: constraint_row, max_row
  use casca_contact_rows, only: constraint_nkinds
  use casca_mass_solver, only: mass_solver_t
  use casca_lapack, only: dpotrf, dpotrs
  implicit none
  private
  public :: contact_correction, add_impulses

  type :: columns_t
    real(dp), allocatable :: x(:, :)
  end type columns_t

contains

  !> Project v and a (full-length, every rank alike) onto the active constraints' persistent
  !> contact: C v+ = 0, C a+ = 0 (with friction, the sticking ones' tangential rows too).
  !> impulse: the velocity's nu (M (v+ - v) = C^T nu); the acceleration's is kept in each
  !> constraint (mu, mut).
  subroutine contact_correction(ms, c, model, v, a, err, impulse)
    type(mass_solver_t), intent(inout) :: ms
    type(contact_t), intent(inout) :: c
    type(model_t), intent(in) :: model
    real(dp), intent(inout) :: v(:), a(:)
    type(error_t), allocatable, intent(out) :: err
    real(dp), intent(out), optional :: impulse(:)
    real(dp), allocatable :: s(:, :), nu(:, :), b(:, :), x(:, :)
    type(columns_t) :: held(3)   ! M^-1 C^T by component
    integer :: nc, r, info, sv, comp, ncomp, j
    integer, allocatable :: comps(:), rk(:), rkind(:)
    if (c%nact == 0) return
    call row_list(c%act(1:c%nact), rk, rkind)
    nc = size(rk)
    allocate (s(nc, nc), nu(nc, 2))
    ! (against a moving obstacle the node keeps the obstacle's speed)
    nu(:, 1) = -[(row_dot(r, v) - obstacle_rate(r), r=1, nc)]
    nu(:, 2) = -[(row_dot(r, a), r=1, nc)]
    ! S = sum over components of B^T M^-1 B (B: the component's part of C^T, as columns);
    ! X = M^-1 B is kept: the corrections are X nu. One MUMPS call per distinct matrix.
    s = 0
    do sv = 1, 3
      comps = pack([1, 2, 3], ms%solver_of == sv .and. ms%neq > 0)
      ncomp = size(comps)
      if (ncomp == 0) cycle
      allocate (b(ms%neq(sv), ncomp*nc), x(ms%neq(sv), ncomp*nc))
      do j = 1, ncomp
        call constraint_columns(ms, c%act(1:c%nact), rk, rkind, model, comps(j), b(:, (j - 1)*nc + 1:j*nc))
      end do
      call ms%solve_sparse(sv, b, x, err)
      if (allocated(err)) return
      do j = 1, ncomp
        call add_sparse_tn(b(:, (j - 1)*nc + 1:j*nc), x(:, (j - 1)*nc + 1:j*nc), s)
        held(comps(j))%x = x(:, (j - 1)*nc + 1:j*nc)
      end do
      deallocate (b, x)
    end do
    s = 0.5_dp*(s + transpose(s))
    call dpotrf('L', nc, s, nc, info)
    if (info /= 0) then
      call fatal_error(err, 'contact correction: dependent constraints (C M^-1 C^T is singular)')
      return
    end if
    call dpotrs('L', nc, 2, s, nc, nu, nc, info)
    if (present(impulse)) impulse = nu(:, 1)
    do r = 1, nc
      if (rkind(r) == 0) then
        c%act(rk(r))%mu = nu(r, 2)
      else
        c%act(rk(r))%mut(rkind(r)) = nu(r, 2)
      end if
    end do
    do comp = 1, 3   ! v += M^-1 C^T nu_v, a += M^-1 C^T nu_a
      if (ms%neq(comp) == 0) cycle
      associate (xc => held(comp)%x, d => ms%dofs(1:ms%neq(comp), comp))
        v(d) = v(d) + matmul(xc, nu(:, 1))
        a(d) = a(d) + matmul(xc, nu(:, 2))
      end associate
    end do
  contains
    !> row r of C times y: a relative rate
    real(dp) function row_dot(r, y)
      integer, intent(in) :: r
      real(dp), intent(in) :: y(:)
      integer :: nd, d(max_row)
      real(dp) :: w(max_row)
      call constraint_row(c%act(rk(r)), model, d, w, nd, rkind(r), force=.true.)
      row_dot = dot_product(w(1:nd), y(d(1:nd)))
    end function row_dot

    !> the obstacle's speed along row r (0 for a body)
    real(dp) function obstacle_rate(r)
      integer, intent(in) :: r
      integer :: t
      t = c%pair(2, c%act(rk(r))%pair)
      obstacle_rate = 0
      if (t > 0) return
      associate (con => c%act(rk(r)))
        if (rkind(r) == 0) then
          obstacle_rate = dot_product(con%n, c%obstacle(-t)%velocity)
        else
          obstacle_rate = dot_product(con%t(:, rkind(r)), c%obstacle(-t)%velocity)
        end if
      end associate
    end function obstacle_rate
  end subroutine contact_correction

  !> The rows of the constraints cons: constraint rk(r) and kind rkind(r) of row r
  subroutine row_list(cons, rk, rkind)
    type(constraint_t), intent(in) :: cons(:)
    integer, allocatable, intent(out) :: rk(:), rkind(:)
    integer :: k, kind, r
    r = sum([(constraint_nkinds(cons(k)), k=1, size(cons))])
    allocate (rk(r), rkind(r))
    r = 0
    do k = 1, size(cons)
      do kind = 0, constraint_nkinds(cons(k)) - 1
        r = r + 1; rk(r) = k; rkind(r) = kind
      end do
    end do
  end subroutine row_list

  !> y = y + M^-1 C^T (lambda - mu) over the constraints cons, every row (one MUMPS call per
  !> distinct matrix): takes the forces they carried out of an acceleration
  subroutine add_impulses(ms, cons, model, y, err)
    type(mass_solver_t), intent(inout) :: ms
    type(constraint_t), intent(in) :: cons(:)
    type(model_t), intent(in) :: model
    real(dp), intent(inout) :: y(:)
    type(error_t), allocatable, intent(out) :: err
    real(dp), allocatable :: b(:, :), x(:, :), bk(:, :), amount(:)
    integer, allocatable :: comps(:), rk(:), rkind(:)
    integer :: sv, j, r
    if (size(cons) == 0) return
    call row_list(cons, rk, rkind)
    allocate (amount(size(rk)))
    do r = 1, size(rk)
      if (rkind(r) == 0) then
        amount(r) = cons(rk(r))%lambda - cons(rk(r))%mu
      else
        amount(r) = cons(rk(r))%lt(rkind(r)) - cons(rk(r))%mut(rkind(r))
      end if
    end do
    do sv = 1, 3
      comps = pack([1, 2, 3], ms%solver_of == sv .and. ms%neq > 0)
      if (size(comps) == 0) cycle
      allocate (b(ms%neq(sv), size(comps)), x(ms%neq(sv), size(comps)))
      allocate (bk(ms%neq(sv), size(rk)))
      do j = 1, size(comps)
        call constraint_columns(ms, cons, rk, rkind, model, comps(j), bk)
        b(:, j) = matmul(bk, amount)
      end do
      deallocate (bk)
      call ms%solve_sparse(sv, b, x, err)
      if (allocated(err)) return
      do j = 1, size(comps)
        associate (dd => ms%dofs(1:ms%neq(comps(j)), comps(j)))
          y(dd) = y(dd) + x(1:ms%neq(comps(j)), j)
        end associate
      end do
      deallocate (b, x)
    end do
  end subroutine add_impulses

  !> s = s + B^T X reading only B's nonzeros (a few per column: one constraint's points):
  !> the dense product cost nc^2 neq, 3 s a step with 961 contacts
  pure subroutine add_sparse_tn(b, x, s)
    real(dp), intent(in) :: b(:, :), x(:, :)
    real(dp), intent(inout) :: s(:, :)
    integer, allocatable :: row(:), col(:)
    integer :: i, j, k, n
    allocate (row(count(b /= 0)), col(count(b /= 0)))
    n = 0
    do i = 1, size(b, 2)
      do k = 1, size(b, 1)
        if (b(k, i) == 0) cycle
        n = n + 1; row(n) = k; col(n) = i
      end do
    end do
    do j = 1, size(x, 2)
      do k = 1, size(row)
        s(col(k), j) = s(col(k), j) + b(row(k), col(k))*x(row(k), j)
      end do
    end do
  end subroutine add_sparse_tn

  !> B (equations of component comp of ms, one column per row (rk, rkind)): the rows of C on
  !> that component's parameters (the mid-surface point's and the fibre's)
  subroutine constraint_columns(ms, cons, rk, rkind, model, comp, b)
    type(mass_solver_t), intent(in) :: ms
    type(constraint_t), intent(in) :: cons(:)
    integer, intent(in) :: rk(:), rkind(:)
    type(model_t), intent(in) :: model
    integer, intent(in) :: comp
    real(dp), intent(out) :: b(:, :)
    integer :: col, j, nd, d(max_row), e
    real(dp) :: w(max_row)
    b = 0
    do col = 1, size(rk)
      call constraint_row(cons(rk(col)), model, d, w, nd, rkind(col), force=.true.)
      do j = 1, nd
        if (mod(mod(d(j) - 1, ndof_node), 3) + 1 /= comp) cycle   ! (Y_comp or G_comp)
        e = ms%eq(d(j))
        if (e > 0) b(e, col) = b(e, col) + w(j)
      end do
    end do
  end subroutine constraint_columns
end module casca_contact_correction
