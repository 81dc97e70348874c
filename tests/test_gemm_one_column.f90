!> dgemm with one column (src/solve/gemm_one_column.c forwards it to dgemv; MUMPS's solution
!> phase calls it so at every Newton iteration): for the four transpositions of A and B, with
!> leading dimensions larger than the matrices, alpha 1.3 and beta 0.7 and 0, the product
!> equals the sum written out in loops to 1e-14 of its largest entry; with two columns
!> (passed to the library's dgemm) likewise.
program test_gemm_one_column
  use casca_kinds, only: dp
  use casca_lapack, only: dgemm
  use casca_check, only: check_le, check_summary
  implicit none
  integer, parameter :: m = 37, k = 23, ld = 41
  real(dp) :: a(ld, ld), b(ld, ld), c(ld, 2), want(m, 2), beta
  character :: ta, tb
  integer :: i, j, n, ib
  call random_seed()
  call random_number(a); call random_number(b)
  a = a - 0.5_dp; b = b - 0.5_dp
  do n = 1, 2
    do ib = 1, 2
      beta = merge(0.7_dp, 0._dp, ib == 1)
      do i = 1, 4
        ta = merge('N', 'T', i <= 2); tb = merge('N', 'T', mod(i, 2) == 1)
        c = 1e3_dp
        do j = 1, n
          want(:, j) = 1.3_dp*matmul(op_a(), op_b(j)) + beta*c(1:m, j)
        end do
        call dgemm(ta, tb, m, n, k, 1.3_dp, a, ld, b, ld, beta, c, ld)
        call check_le('dgemm '//ta//tb//', '//char(48 + n)//' column(s), beta '// &
                      merge('0.7', '0  ', ib == 1)//': largest difference / largest entry', &
                      maxval(abs(c(1:m, 1:n) - want(:, 1:n)))/maxval(abs(want(:, 1:n))), 1e-14_dp)
      end do
    end do
  end do
  call check_summary()
contains
  !> op(A), m x k
  function op_a() result(x)
    real(dp) :: x(m, k)
    if (ta == 'N') then
      x = a(1:m, 1:k)
    else
      x = transpose(a(1:k, 1:m))
    end if
  end function op_a
  !> column j of op(B), k long
  function op_b(j) result(x)
    integer, intent(in) :: j
    real(dp) :: x(k)
    if (tb == 'N') then
      x = b(1:k, j)
    else
      x = b(j, 1:k)
    end if
  end function op_b
end program test_gemm_one_column
