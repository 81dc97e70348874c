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
  use casca_contact, only: contact_t, constraint_t
  use casca_contact_projection, only: row_factors
  use casca_contact_rows, only: constraint_nkinds, start_friction
  use casca_mass_solver, only: mass_solver_t
  use casca_lapack, only: dpotrf, dpotrs, dgemm
  implicit none
  private
  public :: contact_correction, add_impulses, correction_cache_t

  !> Rows of C as scalar rows over the nodes' vector parameters times a direction,
  !> C(r, :) = sum_k w(k) e(node(k), par(k)) (x) dir(:, r), k = ptr(r) .. ptr(r + 1) - 1
  !> (row_factors): M^-1 C^T is then M^-1 G, one column per row whatever the number of
  !> components, and S = C M^-1 C^T is (G^T M^-1 G) o (dir^T dir)
  type :: rows_t
    integer, allocatable :: ptr(:), node(:), par(:)
    real(dp), allocatable :: w(:), dir(:, :)
  end type rows_t

  !> The same rows on the equations of one mass system (restrained parameters left out)
  type :: eq_rows_t
    integer, allocatable :: ptr(:), eq(:)
    real(dp), allocatable :: w(:)
  end type eq_rows_t

  type :: matrix_t
    real(dp), allocatable :: a(:, :)
  end type matrix_t

  !> The Cholesky factor of S, M^-1 G and the rows they were made for: a contact that stays
  !> exactly where it was (a body resting on an obstacle) costs no mass solve and no new
  !> factorisation (a plate lying on a plane, 961 contacts: 11 to 26 ms a step)
  type :: correction_cache_t
    type(rows_t) :: rows
    real(dp), allocatable :: s(:, :)
    type(matrix_t) :: x(3)   !< M^-1 G on each mass system
    logical :: valid = .false.
  end type correction_cache_t

contains

  !> Project v and a (full-length, every rank alike) onto the active constraints' persistent
  !> contact: C v+ = 0, C a+ = 0 (with friction, the sticking ones' tangential rows too).
  !> impulse: the velocity's nu (M (v+ - v) = C^T nu); the acceleration's is kept in each
  !> constraint (mu, mut). loss: per row, its share of the kinetic energy the correction takes
  !> out, -nu_r ((C v)_r + r_r) / 2 with r the obstacle's rate (they sum to it exactly:
  !> M^-1-weighted, the change is nu . C v + nu . S nu / 2 and S nu = r - C v).
  subroutine contact_correction(ms, cache, c, model, v, a, err, impulse, loss)
    type(mass_solver_t), intent(inout) :: ms
    type(correction_cache_t), intent(inout) :: cache
    type(contact_t), intent(inout) :: c
    type(model_t), intent(in) :: model
    real(dp), intent(inout) :: v(:), a(:)
    type(error_t), allocatable, intent(out) :: err
    real(dp), intent(out), optional :: impulse(:), loss(:)
    real(dp), allocatable :: nu(:, :), dva(:, :), rate(:), cv(:)
    type(rows_t) :: rows
    integer :: nc, r, info
    integer, allocatable :: rk(:), rkind(:)
    logical :: same
    if (c%set%nact == 0) return
    call row_list(c%set%act(1:c%set%nact), rk, rkind)
    nc = size(rk)
    call build_rows(c%set%act(1:c%set%nact), rk, rkind, model, rows)
    allocate (nu(nc, 2))
    ! (against a moving obstacle the node keeps the obstacle's speed)
    rate = [(obstacle_rate(r), r=1, nc)]
    cv = [(row_dot(rows, r, v), r=1, nc)]
    nu(:, 1) = rate - cv
    nu(:, 2) = -[(row_dot(rows, r, a), r=1, nc)]
    same = cache%valid
    if (same) same = same_rows(rows, cache%rows)
    if (.not. same) then
      cache%valid = .false.
      if (allocated(cache%s)) then
        if (size(cache%s, 1) /= nc) deallocate (cache%s)
      end if
      if (.not. allocated(cache%s)) allocate (cache%s(nc, nc))
      cache%s = 0
      call mass_images(ms, rows, cache%x, err, cache%s)
      if (allocated(err)) return
      call dpotrf('L', nc, cache%s, nc, info)
      if (info /= 0) then
        call fatal_error(err, 'contact correction: dependent constraints (C M^-1 C^T is singular)')
        return
      end if
      cache%rows = rows
      cache%valid = .true.
    end if
    call dpotrs('L', nc, 2, cache%s, nc, nu, nc, info)
    if (present(impulse)) impulse = nu(:, 1)
    if (present(loss)) loss = -nu(:, 1)*(cv + rate)/2
    do r = 1, nc
      if (rkind(r) == 0) then
        c%set%act(rk(r))%mu = nu(r, 2)
      else
        c%set%act(rk(r))%mut(rkind(r)) = nu(r, 2)
      end if
    end do
    dva = images(ms, cache%x, cache%rows%dir, nu, size(v))   ! v += M^-1 C^T nu_v, a likewise
    v = v + dva(:, 1)
    a = a + dva(:, 2)
  contains
    !> the obstacle's speed along row r (0 for a body)
    real(dp) function obstacle_rate(r)
      integer, intent(in) :: r
      integer :: t
      t = c%pair(2, c%set%act(rk(r))%pair)
      obstacle_rate = 0
      if (t > 0) return
      obstacle_rate = dot_product(rows%dir(:, r), c%obstacle(-t)%velocity)
    end function obstacle_rate
  end subroutine contact_correction

  !> row r of C times y: a relative rate
  pure real(dp) function row_dot(rows, r, y)
    type(rows_t), intent(in) :: rows
    integer, intent(in) :: r
    real(dp), intent(in) :: y(:)
    integer :: k, d
    row_dot = 0
    do k = rows%ptr(r), rows%ptr(r + 1) - 1
      d = dof(rows%node(k), 1 + 3*rows%par(k))
      row_dot = row_dot + rows%w(k)*dot_product(rows%dir(:, r), y(d:d + 2))
    end do
  end function row_dot

  pure logical function same_rows(x, y)
    type(rows_t), intent(in) :: x, y
    same_rows = .false.
    if (size(x%ptr) /= size(y%ptr)) return
    if (any(x%ptr /= y%ptr)) return
    associate (n => x%ptr(size(x%ptr)) - 1)
      same_rows = all(x%node(1:n) == y%node(1:n)) .and. all(x%par(1:n) == y%par(1:n)) .and. &
                  all(x%w(1:n) == y%w(1:n)) .and. all(x%dir == y%dir)
    end associate
  end function same_rows

  !> x(sv)%a = M^-1 G on each mass system sv (G: rows on its equations), and with s, S's
  !> lower triangle accumulated over the systems
  subroutine mass_images(ms, rows, x, err, s)
    type(mass_solver_t), intent(inout) :: ms
    type(rows_t), intent(in) :: rows
    type(matrix_t), intent(inout) :: x(3)
    type(error_t), allocatable, intent(out) :: err
    real(dp), intent(inout), optional :: s(:, :)
    type(eq_rows_t) :: g
    integer :: sv
    do sv = 1, 3
      if (.not. any(ms%solver_of == sv .and. ms%neq > 0)) cycle
      call system_rows(ms, sv, rows, g)
      call ms%columns(sv, g%ptr, g%eq(1:g%ptr(size(g%ptr)) - 1), g%w, x(sv)%a, err)
      if (allocated(err)) return
      if (present(s)) call add_schur(g, x(sv)%a, rows%dir(pack([1, 2, 3], ms%solver_of == sv), :), s)
    end do
  end subroutine mass_images

  !> M^-1 C^T coef for each column of coef (ndof, its columns), component by component from
  !> x = M^-1 G (mass_images) and the rows' directions, all columns in one product (BLAS:
  !> gfortran's matmul took 26 ms a step for 961 contacts, twice the rest of the correction)
  function images(ms, x, dir, coef, ndof) result(dy)
    type(mass_solver_t), intent(in) :: ms
    type(matrix_t), intent(in) :: x(3)
    real(dp), intent(in) :: dir(:, :), coef(:, :)
    integer, intent(in) :: ndof
    real(dp), allocatable :: dy(:, :), t(:, :)
    integer :: comp, nc, k
    nc = size(coef, 1); k = size(coef, 2)
    allocate (dy(ndof, k), t(ndof, k))
    dy = 0
    do comp = 1, 3
      if (ms%neq(comp) == 0) cycle
      associate (n => ms%neq(comp), d => ms%dofs(1:ms%neq(comp), comp))
        call dgemm('N', 'N', n, k, nc, 1._dp, x(ms%solver_of(comp))%a, n, &
                   spread(dir(comp, :), 2, k)*coef, nc, 0._dp, t, ndof)
        dy(d, :) = t(1:n, :)
      end associate
    end do
  end function images

  !> s = s + (G^T X) o (dir^T dir), X = M^-1 G, dir over the system's components: one
  !> system's share of C M^-1 C^T, its lower triangle (what dpotrf reads), from G's nonzeros
  !> only (a few per column: one constraint's points)
  pure subroutine add_schur(g, x, dir, s)
    type(eq_rows_t), intent(in) :: g
    real(dp), intent(in) :: x(:, :), dir(:, :)
    real(dp), intent(inout) :: s(:, :)
    integer :: i, j, k
    real(dp) :: t
    do j = 1, size(s, 2)
      do i = j, size(s, 1)
        t = 0
        do k = g%ptr(i), g%ptr(i + 1) - 1
          t = t + g%w(k)*x(g%eq(k), j)
        end do
        s(i, j) = s(i, j) + t*dot_product(dir(:, i), dir(:, j))
      end do
    end do
  end subroutine add_schur

  !> The rows (rk, rkind) of the constraints cons, each at its force's point
  subroutine build_rows(cons, rk, rkind, model, rows)
    type(constraint_t), intent(in) :: cons(:)
    integer, intent(in) :: rk(:), rkind(:)
    type(model_t), intent(in) :: model
    type(rows_t), intent(out) :: rows
    integer :: r, k, nw
    allocate (rows%ptr(size(rk) + 1), rows%node(22*size(rk)), rows%par(22*size(rk)), &
              rows%w(22*size(rk)), rows%dir(3, size(rk)))
    k = 0
    do r = 1, size(rk)
      rows%ptr(r) = k + 1
      call row_factors(cons(rk(r)), model, rkind(r), .true., rows%node(k + 1:k + 22), &
                       rows%par(k + 1:k + 22), rows%w(k + 1:k + 22), nw, rows%dir(:, r), point=.true.)
      k = k + nw
    end do
    rows%ptr(size(rk) + 1) = k + 1
  end subroutine build_rows

  !> rows on the equations of mass system sv (its components share their numbering)
  subroutine system_rows(ms, sv, rows, g)
    type(mass_solver_t), intent(in) :: ms
    integer, intent(in) :: sv
    type(rows_t), intent(in) :: rows
    type(eq_rows_t), intent(inout) :: g
    integer :: r, k, e, n, c0
    c0 = findloc(ms%solver_of, sv, dim=1)
    n = size(rows%ptr) - 1
    if (allocated(g%ptr)) deallocate (g%ptr, g%eq, g%w)
    allocate (g%ptr(n + 1), g%eq(rows%ptr(n + 1) - 1), g%w(rows%ptr(n + 1) - 1))
    e = 0
    do r = 1, n
      g%ptr(r) = e + 1
      do k = rows%ptr(r), rows%ptr(r + 1) - 1
        if (ms%eq(dof(rows%node(k), c0 + 3*rows%par(k))) == 0) cycle
        e = e + 1; g%eq(e) = ms%eq(dof(rows%node(k), c0 + 3*rows%par(k))); g%w(e) = rows%w(k)
      end do
    end do
    g%ptr(n + 1) = e + 1
  end subroutine system_rows

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

  !> y = y + M^-1 C^T (share lambda - mu) over the constraints cons, every row, and a sliding
  !> one's friction with its force, - share fa: takes the forces they carried out of an
  !> acceleration (a ring spinning up on a floor, whose nodes land and lift off in turn, kept
  !> each lifted node's friction in its next step's start: 0.3224 of the normal impulse at
  !> mu 0.3; now 0.3003)
  subroutine add_impulses(ms, cons, model, y, err, share)
    type(mass_solver_t), intent(inout) :: ms
    type(constraint_t), intent(in) :: cons(:)
    type(model_t), intent(in) :: model
    real(dp), intent(inout) :: y(:)
    type(error_t), allocatable, intent(out) :: err
    real(dp), intent(in) :: share   !< of a multiplier in the end acceleration (1: Newmark)
    type(rows_t) :: rows
    type(matrix_t) :: x(3)
    real(dp), allocatable :: amount(:), dy(:, :), f(:, :)
    integer, allocatable :: rk(:), rkind(:)
    integer :: r, n
    if (size(cons) == 0) return
    call row_list(cons, rk, rkind)
    n = size(rk)
    allocate (amount(n))
    do r = 1, n
      if (rkind(r) == 0) then
        amount(r) = share*cons(rk(r))%lambda - cons(rk(r))%mu
      else
        amount(r) = share*cons(rk(r))%lt(rkind(r)) - cons(rk(r))%mut(rkind(r))
      end if
    end do
    call build_rows(cons, rk, rkind, model, rows)
    call mass_images(ms, rows, x, err)
    if (allocated(err)) return
    ! (each row's whole force as its direction, times 1)
    f = rows%dir*spread(amount, 1, 3)
    do r = 1, n
      if (rkind(r) == 0) f(:, r) = f(:, r) - share*start_friction(cons(rk(r)))
    end do
    dy = images(ms, x, f, reshape([(1._dp, r=1, n)], [n, 1]), size(y))
    y = y + dy(:, 1)
  end subroutine add_impulses
end module casca_contact_correction
