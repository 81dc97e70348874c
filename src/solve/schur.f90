!> The Schur complement of K in the saddle-point system, kept column by column:
!> Z = K^-1 B^T (the rows of this rank's blocks; zero elsewhere) and S = C Z (replicated),
!> with the rows they were made from. Column j of Z depends only on K's factors and on row
!> j's entries, so while the factors stay a constraint whose row is unchanged (same key,
!> same entries, bit for bit) keeps its column and only new or changed rows cost a solve;
!> likewise S(i, j) = c_i . z_j stays for two kept rows. S is symmetric positive definite
!> when K is and the constraints are independent, so it is factorised by Cholesky, whose
!> success is the inertia check (the saddle-point matrix then has K's inertia plus nc
!> negative eigenvalues). When Cholesky fails (K indefinite, as past a limit point) S is
!> decomposed into eigenvalues; a (nearly) singular S, relative to its largest eigenvalue,
!> means dependent constraints, or K near-singular where they hold it (S's largest
!> eigenvalues blow up: a buckled ring between planes), and is an error that cuts the step
!> (under solver = 'auto', takes it again through the saddle-point matrix), never a silent
!> zero correction.
module casca_schur
  use casca_kinds, only: dp
  use casca_error, only: error_t, fatal_error
  use casca_mpi, only: sum_all
  use casca_lapack, only: dsyev, dpotrf, dpotrs, dgetrf, dgetrs
  implicit none
  private
  public :: schur_t, schur_match, schur_store, schur_apply, match_rows

  type :: schur_t
    real(dp), allocatable :: z(:, :)      !< (neq, nc) K^-1 B^T, one column per row
    real(dp), allocatable :: cz(:, :)     !< (nc, nc) this rank's part of S = C Z
    real(dp), allocatable :: s(:, :)      !< Cholesky factor of S, its LU, or its eigenvectors
    real(dp), allocatable :: eig(:)       !< eigenvalues of S when not Cholesky
    integer, allocatable :: irn(:), jcn(:), key(:, :)
    real(dp), allocatable :: val(:), fval(:)
    integer, allocatable :: first(:)      !< (nc + 1) the entries of row k: first(k) .. first(k+1)-1
    logical :: current = .false.          !< made with the factors of K in use
    logical :: cholesky = .true.
    integer, allocatable :: pivots(:)     !< LU's, when S is unsymmetric (sliding friction)
    integer :: positive = 0               !< positive eigenvalues of S
    integer :: kept = 0, made = 0         !< columns kept and made, over the run
  end type schur_t

contains

  !> For each row of the new set, the cached column it can keep (0: a new column is needed)
  !> while the factors of K are those the cache was made with: a row of the same key and
  !> pattern; exact where its values are the same too (match_rows). The rows hold each
  !> rank's own equations, so the ranks' verdicts are pooled: all keep a column, or none.
  subroutine schur_match(c, irn, jcn, val, fval, key, col, exact)
    type(schur_t), intent(in) :: c
    integer, intent(in) :: irn(:), jcn(:), key(:, :)
    real(dp), intent(in) :: val(:), fval(:)
    integer, intent(out) :: col(:)
    logical, intent(out) :: exact(:)
    logical, allocatable :: same(:)
    real(dp), allocatable :: differ(:, :)
    col = 0; exact = .false.
    if (.not. (c%current .and. allocated(c%key))) return
    allocate (same(size(col)))
    call match_rows(c%irn, c%jcn, c%val, c%fval, c%key, irn, jcn, val, fval, key, col, same, exact)
    differ = reshape([merge(0._dp, 1._dp, same), merge(0._dp, 1._dp, exact)], [size(col), 2])
    call sum_all(differ)
    where (differ(:, 1) > 0) col = 0
    exact = col > 0 .and. differ(:, 2) == 0
  end subroutine schur_match

  !> For each new row (entries irn, jcn, val, fval in row order, rows after the equations,
  !> each ending with its diagonal; key), the old row of the same key (0: none; keys are
  !> replicated, so every rank picks the same), whether its pattern is the same (same) and
  !> its values too, bit for bit (exact). Rows mostly keep their order, so the row after the
  !> last one matched is tried first.
  pure subroutine match_rows(oirn, ojcn, oval, ofval, okey, irn, jcn, val, fval, key, col, same, exact)
    integer, intent(in) :: oirn(:), ojcn(:), okey(:, :), irn(:), jcn(:), key(:, :)
    real(dp), intent(in) :: oval(:), ofval(:), val(:), fval(:)
    integer, intent(out) :: col(:)
    logical, intent(out) :: same(:), exact(:)
    integer, allocatable :: first(:), ofirst(:)
    logical, allocatable :: taken(:)
    integer :: k, j, guess, nold
    col = 0; same = .false.; exact = .false.
    nold = size(okey, 2)
    allocate (taken(nold))
    taken = .false.
    call row_starts(irn, size(key, 2), first)
    call row_starts(oirn, nold, ofirst)
    guess = 1
    do k = 1, size(key, 2)
      if (guess <= nold) then
        if (free_key(k, guess)) col(k) = guess
      end if
      if (col(k) == 0) then
        do j = 1, nold
          if (free_key(k, j)) then
            col(k) = j; exit
          end if
        end do
      end if
      if (col(k) > 0) then
        taken(col(k)) = .true.; guess = col(k) + 1
        call compare(k, col(k), same(k), exact(k))
      end if
    end do
  contains
    pure logical function free_key(k, j)
      integer, intent(in) :: k, j
      free_key = .not. taken(j) .and. all(key(:, k) == okey(:, j))
    end function free_key

    !> same: the entries on the same equations (the last, the row's diagonal, is numbered by
    !> its place); exact: with the same values too
    pure subroutine compare(k, j, same_k, exact_k)
      integer, intent(in) :: k, j
      logical, intent(out) :: same_k, exact_k
      integer :: a, b, n
      a = first(k); b = ofirst(j); n = first(k + 1) - a
      same_k = .false.; exact_k = .false.
      if (ofirst(j + 1) - b /= n) return
      same_k = all(jcn(a:a + n - 2) == ojcn(b:b + n - 2))
      exact_k = same_k .and. all(val(a:a + n - 1) == oval(b:b + n - 1)) .and. &
                 all(fval(a:a + n - 1) == ofval(b:b + n - 1))
    end subroutine compare
  end subroutine match_rows

  !> Keep the new rows and Z: column k is the cached column col(k), or, where col(k) = 0,
  !> the next column of znew (K^-1 B^T of the new rows, in row order). A kept row keeps the
  !> values its column was made with (an earlier iterate's, unless exact): Z, S and the
  !> rows of the cache stay one saddle-point system, an approximate one like K's kept
  !> factors. S = C Z is taken over where both row and column are kept, computed where
  !> either is new, summed over the ranks and factorised (by LU when B /= C: sliding friction).
  subroutine schur_store(c, neq, irn, jcn, val, fval, key, col, znew, err)
    type(schur_t), intent(inout) :: c
    integer, intent(in) :: neq, irn(:), jcn(:), key(:, :), col(:)
    real(dp), intent(in) :: val(:), fval(:), znew(:, :)
    type(error_t), allocatable, intent(out) :: err
    real(dp), allocatable :: z(:, :), cz(:, :), v(:), fv(:)
    integer, allocatable :: first(:)
    integer :: nc, k, i, m, n, a, b
    integer :: unsym   !< entries where B differs from C, over the ranks
    nc = size(key, 2)
    allocate (z(neq, nc), cz(nc, nc))
    v = val; fv = fval
    call row_starts(irn, nc, first)
    m = 0
    do k = 1, nc
      if (col(k) > 0) then
        z(:, k) = c%z(:, col(k))
        do i = 1, nc
          if (col(i) > 0) cz(i, k) = c%cz(col(i), col(k))
        end do
        a = first(k); b = c%first(col(k)); n = first(k + 1) - a
        v(a:a + n - 1) = c%val(b:b + n - 1); fv(a:a + n - 1) = c%fval(b:b + n - 1)
      else
        m = m + 1
        z(:, k) = znew(:, m)
      end if
    end do
    c%kept = c%kept + (nc - m); c%made = c%made + m
    call move_alloc(z, c%z); call move_alloc(cz, c%cz)
    c%irn = irn; c%jcn = jcn; c%key = key
    call move_alloc(v, c%val); call move_alloc(fv, c%fval); call move_alloc(first, c%first)
    call new_products(c, neq, col)
    c%current = .true.
    ! each rank holds only its equations' entries of a row, so whether B differs from C is
    ! pooled: a rank that saw none took S as symmetric and solved for other multipliers than
    ! the rest (two balls glancing on 2 ranks kept the momentum to 2.7e-9 only, now 6e-14)
    unsym = count(c%fval /= c%val)
    call sum_all(unsym)
    call factorise_s(c, unsym > 0, err)
  end subroutine schur_store

  !> The entries of S = C Z (this rank's part) whose row or column is new (col = 0)
  subroutine new_products(c, neq, col)
    type(schur_t), intent(inout) :: c
    integer, intent(in) :: neq, col(:)
    integer :: e, j, i
    do j = 1, size(col)
      if (col(j) == 0) then   ! a new column: every row
        c%cz(:, j) = 0
        do e = 1, size(c%irn)
          if (c%irn(e) /= c%jcn(e)) c%cz(c%irn(e) - neq, j) = c%cz(c%irn(e) - neq, j) + c%val(e)*c%z(c%jcn(e), j)
        end do
      else                    ! a kept column: the new rows only
        do i = 1, size(col)
          if (col(i) > 0) cycle
          c%cz(i, j) = 0
          do e = c%first(i), c%first(i + 1) - 1
            if (c%irn(e) /= c%jcn(e)) c%cz(i, j) = c%cz(i, j) + c%val(e)*c%z(c%jcn(e), j)
          end do
        end do
      end if
    end do
  end subroutine new_products

  !> S (the ranks' parts summed) by Cholesky; by LU when unsym; into eigenvalues when S is
  !> not positive definite. positive: S's positive eigenvalues (all of them with LU).
  subroutine factorise_s(c, unsym, err)
    type(schur_t), intent(inout) :: c
    logical, intent(in) :: unsym
    type(error_t), allocatable, intent(out) :: err
    real(dp), allocatable :: work(:)
    integer :: nc, info
    nc = size(c%cz, 1)
    if (allocated(c%pivots)) deallocate (c%pivots)
    call assemble_s()
    if (unsym) then
      c%cholesky = .false.
      allocate (c%pivots(nc))
      call dgetrf(nc, nc, c%s, nc, c%pivots, info)
      c%positive = nc
      if (info /= 0) call dependent()
      return
    end if
    c%s = 0.5_dp*(c%s + transpose(c%s))
    c%cholesky = .true.
    call dpotrf('L', nc, c%s, nc, info)
    if (info == 0) then
      c%positive = nc
      return
    end if
    c%cholesky = .false.   ! not positive definite: S again, into eigenvalues
    call assemble_s()
    c%s = 0.5_dp*(c%s + transpose(c%s))
    if (allocated(c%eig)) deallocate (c%eig)
    allocate (c%eig(nc), work(max(1, 4*nc)))
    call dsyev('V', 'L', nc, c%s, nc, c%eig, work, size(work), info)
    c%positive = count(c%eig > 0)
    if (info /= 0 .or. minval(abs(c%eig)) <= 1e-12_dp*maxval(abs(c%eig))) call dependent()
  contains
    !> S = C Z summed over the ranks, less the rows' own diagonal (a compliant row's
    !> -compliance: the saddle matrix's (2, 2) block), once
    subroutine assemble_s()
      integer :: k
      c%s = c%cz
      call sum_all(c%s)
      do k = 1, nc   ! (a row's diagonal is its last entry)
        c%s(k, k) = c%s(k, k) - c%val(c%first(k + 1) - 1)
      end do
    end subroutine assemble_s

    subroutine dependent()
      c%current = .false.
      call fatal_error(err, 'singular Schur complement of the contact constraints (they are dependent, '// &
                       'or the stiffness is near-singular where they hold it)')
    end subroutine dependent
  end subroutine factorise_s

  !> first(k): the first entry of row k (entries in row order; rows neq + 1 .. neq + nr)
  pure subroutine row_starts(irn, nr, first)
    integer, intent(in) :: irn(:), nr
    integer, allocatable, intent(out) :: first(:)
    integer :: e, r0
    allocate (first(nr + 1))
    first(nr + 1) = size(irn) + 1
    if (nr == 0) return
    r0 = minval(irn) - 1   ! neq: every row has at least its diagonal entry
    do e = size(irn), 1, -1
      first(irn(e) - r0) = e
    end do
  end subroutine row_starts

  !> x = [y - Z dlambda; dlambda] with S dlambda = C y + gap, the rows and S of the cache
  !> (y = K^-1 b of this rank's blocks).
  subroutine schur_apply(c, neq, y, gap, x)
    type(schur_t), intent(in) :: c
    integer, intent(in) :: neq
    real(dp), intent(in) :: y(:), gap(:)
    real(dp), intent(out) :: x(:)
    real(dp), allocatable :: rhs(:)
    integer :: e, k, nc, info
    nc = size(gap)
    allocate (rhs(nc))
    rhs = 0
    do e = 1, size(c%irn)
      if (c%irn(e) == c%jcn(e)) cycle
      k = c%irn(e) - neq
      rhs(k) = rhs(k) + c%val(e)*y(c%jcn(e))
    end do
    call sum_all(rhs)
    rhs = rhs + gap
    if (allocated(c%pivots)) then
      call dgetrs('N', nc, 1, c%s, nc, c%pivots, rhs, nc, info)
    else if (c%cholesky) then
      call dpotrs('L', nc, 1, c%s, nc, rhs, nc, info)
    else
      rhs = matmul(c%s, matmul(rhs, c%s)/c%eig)
    end if
    x(1:neq) = y - matmul(c%z, rhs)
    x(neq + 1:) = rhs
  end subroutine schur_apply
end module casca_schur
