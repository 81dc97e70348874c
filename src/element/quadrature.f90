!> Quadrature rules: symmetric rules on the reference triangle (weights sum to its area, 1/2)
!> and Gauss-Legendre rules on [-1, 1] through the thickness.
module casca_quadrature
  use casca_kinds, only: dp
  use casca_error, only: error_t, fatal_error
  implicit none
  private
  public :: triangle_rule, gauss_rule

contains

  !> Symmetric triangle rule with npts points: 7 (degree 5, Radon) or 12 (degree 6, Dunavant).
  subroutine triangle_rule(npts, xi, w, err)
    integer, intent(in) :: npts
    real(dp), allocatable, intent(out) :: xi(:, :), w(:)
    type(error_t), allocatable, intent(out) :: err
    real(dp) :: r15
    integer :: k

    allocate (xi(2, npts), w(npts))
    k = 0
    select case (npts)
    case (7)
      r15 = sqrt(15._dp)
      call centroid(9._dp/40)
      call orbit3((6 - r15)/21, (155 - r15)/1200)
      call orbit3((6 + r15)/21, (155 + r15)/1200)
    case (12)
      call orbit3(0.249286745170910_dp, 0.116786275726379_dp)
      call orbit3(0.063089014491502_dp, 0.050844906370207_dp)
      call orbit6(0.053145049844817_dp, 0.310352451033784_dp, 0.082851075618374_dp)
    case default
      call fatal_error(err, 'triangle quadrature: 7 or 12 points are available')
      return
    end select
    w = 0.5_dp*w/sum(w)   ! weights above sum to 1; the reference triangle has area 1/2
  contains
    subroutine centroid(wt)
      real(dp), intent(in) :: wt
      k = k + 1; xi(:, k) = 1._dp/3; w(k) = wt
    end subroutine centroid
    !> the three points with barycentric coordinates (1-2b, b, b) and permutations
    subroutine orbit3(b, wt)
      real(dp), intent(in) :: b, wt
      real(dp) :: a
      a = 1 - 2*b
      xi(:, k + 1) = [b, b]; xi(:, k + 2) = [a, b]; xi(:, k + 3) = [b, a]
      w(k + 1:k + 3) = wt; k = k + 3
    end subroutine orbit3
    !> the six permutations of barycentric (a, b, 1-a-b)
    subroutine orbit6(a, b, wt)
      real(dp), intent(in) :: a, b, wt
      real(dp) :: c
      c = 1 - a - b
      xi(:, k + 1) = [a, b]; xi(:, k + 2) = [b, a]; xi(:, k + 3) = [a, c]
      xi(:, k + 4) = [c, a]; xi(:, k + 5) = [b, c]; xi(:, k + 6) = [c, b]
      w(k + 1:k + 6) = wt; k = k + 6
    end subroutine orbit6
  end subroutine triangle_rule

  !> Gauss-Legendre rule with 1 to 3 points on [-1, 1].
  subroutine gauss_rule(npts, z, w, err)
    integer, intent(in) :: npts
    real(dp), allocatable, intent(out) :: z(:), w(:)
    type(error_t), allocatable, intent(out) :: err
    select case (npts)
    case (1)
      z = [0._dp]; w = [2._dp]
    case (2)
      z = [-1._dp, 1._dp]/sqrt(3._dp); w = [1._dp, 1._dp]
    case (3)
      z = [-sqrt(0.6_dp), 0._dp, sqrt(0.6_dp)]; w = [5._dp, 8._dp, 5._dp]/9
    case default
      allocate (z(0), w(0))
      call fatal_error(err, 'thickness quadrature: 1 to 3 Gauss points are available')
    end select
  end subroutine gauss_rule
end module casca_quadrature
