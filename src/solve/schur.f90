!> The Schur complement of K in the saddle-point system, kept between iterations:
!> Z = K^-1 C^T (the rows of this rank's blocks; zero elsewhere) and S = C Z (replicated),
!> with the rows they were made from. S is symmetric positive definite when K is and the
!> constraints are independent, so it is factorised by Cholesky; the inertia of the
!> saddle-point matrix is then that of K plus nc negative eigenvalues. When Cholesky fails
!> (K indefinite, as past a limit point) S is decomposed into eigenvalues; a (nearly)
!> singular S means dependent constraints and is an error that cuts the step, never a
!> silent zero correction.
module casca_schur
  use casca_kinds, only: dp
  use casca_error, only: error_t, fatal_error
  use casca_mpi, only: sum_all
  use casca_lapack, only: dsyev, dpotrf, dpotrs, dgetrf, dgetrs
  implicit none
  private
  public :: schur_t, schur_valid, schur_store, schur_apply

  type :: schur_t
    real(dp), allocatable :: z(:, :)      !< (neq, nc) K^-1 C^T
    real(dp), allocatable :: s(:, :)      !< Cholesky factor of S, or its eigenvectors
    real(dp), allocatable :: eig(:)       !< eigenvalues of S when not Cholesky
    integer, allocatable :: irn(:), jcn(:), key(:, :)
    real(dp), allocatable :: val(:)
    logical :: current = .false.          !< made with the factors of K in use
    logical :: cholesky = .true.
    integer, allocatable :: pivots(:)     !< LU's, when S is unsymmetric (sliding friction)
    integer :: positive = 0               !< positive eigenvalues of S
  end type schur_t

contains

  !> The cache holds Z and S for these constraints (key: node and element of each row) and
  !> the factors of K in use.
  logical function schur_valid(c, key)
    type(schur_t), intent(in) :: c
    integer, intent(in) :: key(:, :)
    schur_valid = c%current .and. allocated(c%key)
    if (.not. schur_valid) return
    schur_valid = size(c%key, 2) == size(key, 2)
    if (schur_valid) schur_valid = all(c%key == key)
  end function schur_valid

  !> Keep the rows and Z, form S = C Z (summed over the ranks) and factorise it.
  !> unsym: Z = K^-1 B^T with B /= C: S is factorised by LU (its inertia is not counted)
  subroutine schur_store(c, neq, irn, jcn, val, key, z, err, unsym)
    type(schur_t), intent(inout) :: c
    integer, intent(in) :: neq, irn(:), jcn(:), key(:, :)
    real(dp), intent(in) :: val(:), z(:, :)
    type(error_t), allocatable, intent(out) :: err
    logical, intent(in) :: unsym
    real(dp), allocatable :: work(:)
    integer :: nc, info
    nc = size(key, 2)
    c%irn = irn; c%jcn = jcn; c%val = val; c%key = key; c%z = z
    c%current = .true.
    if (allocated(c%pivots)) deallocate (c%pivots)
    call form_s()
    if (unsym) then
      c%cholesky = .false.
      allocate (c%pivots(nc))
      call dgetrf(nc, nc, c%s, nc, c%pivots, info)
      c%positive = nc
      if (info /= 0) then
        c%current = .false.
        call fatal_error(err, 'contact constraints are dependent (singular Schur complement)')
      end if
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
    call form_s()
    c%s = 0.5_dp*(c%s + transpose(c%s))
    if (allocated(c%eig)) deallocate (c%eig)
    allocate (c%eig(nc), work(max(1, 4*nc)))
    call dsyev('V', 'L', nc, c%s, nc, c%eig, work, size(work), info)
    c%positive = count(c%eig > 0)
    if (info /= 0 .or. minval(abs(c%eig)) <= 1e-12_dp*maxval(abs(c%eig))) then
      c%current = .false.
      call fatal_error(err, 'contact constraints are dependent (singular Schur complement)')
    end if
  contains
    subroutine form_s()
      integer :: e, k
      if (allocated(c%s)) deallocate (c%s)
      allocate (c%s(nc, nc))
      c%s = 0
      do e = 1, size(irn)
        if (irn(e) == jcn(e)) cycle
        k = irn(e) - neq
        c%s(k, :) = c%s(k, :) + val(e)*z(jcn(e), :)
      end do
      call sum_all(c%s)
    end subroutine form_s
  end subroutine schur_store

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
