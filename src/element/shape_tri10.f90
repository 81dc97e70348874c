!> Cubic Lagrange shape functions of the 10-node triangle (node order: see casca_mesh).
module casca_shape_tri10
  use casca_kinds, only: dp
  use casca_vectors, only: cross
  implicit none
  private
  public :: tri10_shape, tri10_normal, tri10_node_xi, subtri10

  !> Reference coordinates (xi1, xi2) of the 10 nodes.
  real(dp), parameter :: tri10_node_xi(2, 10) = reshape([ &
      0._dp, 0._dp,   1._dp, 0._dp,   0._dp, 1._dp, &
      1._dp/3, 0._dp,   2._dp/3, 0._dp, &
      2._dp/3, 1._dp/3, 1._dp/3, 2._dp/3, &
      0._dp, 2._dp/3,   0._dp, 1._dp/3, &
      1._dp/3, 1._dp/3], [2, 10])

  !> The 9 linear sub-triangles of the cubic node lattice (used for contact detection and
  !> for drawing), each oriented like its parent element.
  integer, parameter :: subtri10(3, 9) = reshape([ &
      1, 4, 9,   4, 5, 10,   4, 10, 9,   5, 2, 6,   5, 6, 10, &
      9, 10, 8,  10, 6, 7,   10, 7, 8,   8, 7, 3], [3, 9])

contains

  !> phi(l) and dphi(l, j) = d phi_l / d xi_j at (xi1, xi2).
  pure subroutine tri10_shape(xi1, xi2, phi, dphi)
    real(dp), intent(in) :: xi1, xi2
    real(dp), intent(out) :: phi(10), dphi(10, 2)
    real(dp) :: l(3), dl(3, 2), f(3), df(3)
    integer, parameter :: ea(6) = [1, 2, 2, 3, 3, 1]   ! edge nodes 4..9: nearer vertex ...
    integer, parameter :: eb(6) = [2, 1, 3, 2, 1, 3]   ! ... and the other vertex of the edge
    integer :: i, a, b

    l = [1._dp - xi1 - xi2, xi1, xi2]
    dl = reshape([-1._dp, 1._dp, 0._dp, -1._dp, 0._dp, 1._dp], [3, 2])
    ! vertices: L(3L-1)(3L-2)/2
    f = 0.5_dp*l*(3*l - 1)*(3*l - 2)
    df = 0.5_dp*(27*l*l - 18*l + 2)
    do i = 1, 3
      phi(i) = f(i)
      dphi(i, :) = df(i)*dl(i, :)
    end do
    ! edge nodes: 9/2 La Lb (3La - 1), a the nearer vertex
    do i = 1, 6
      a = ea(i); b = eb(i)
      phi(3 + i) = 4.5_dp*l(a)*l(b)*(3*l(a) - 1)
      dphi(3 + i, :) = 4.5_dp*(l(b)*(6*l(a) - 1)*dl(a, :) + l(a)*(3*l(a) - 1)*dl(b, :))
    end do
    phi(10) = 27*l(1)*l(2)*l(3)
    dphi(10, :) = 27*(l(2)*l(3)*dl(1, :) + l(1)*l(3)*dl(2, :) + l(1)*l(2)*dl(3, :))
  end subroutine tri10_shape

  !> Normal of the cubic surface through the 10 points xe, where the shape derivatives are
  !> dphi: the cross product of the two tangents (its length is the area Jacobian).
  pure function tri10_normal(xe, dphi) result(n)
    real(dp), intent(in) :: xe(3, 10), dphi(10, 2)
    real(dp) :: n(3)
    n = cross(matmul(xe, dphi(:, 1)), matmul(xe, dphi(:, 2)))
  end function tri10_normal
end module casca_shape_tri10
