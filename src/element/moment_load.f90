!> A moment m about a fixed axis e = m/|m| on one node's fibre G, the direction of the cross-
!> section (y = Y + h/2 (xi3 + a xi3^2) G): the conservative load whose potential is
!> -|m| theta, theta the angle G has turned about e. With G_p = G - (G.e) e, the part of G
!> across the axis,
!>
!>   f = m x G / |G_p|^2,                    (d theta/dG = e x G / |G_p|^2)
!>   df/dG = ([m]x - 2 (m x G) G_p^T / |G_p|^2) / |G_p|^2,
!>
!> symmetric, as a potential's Hessian is. Only the angle of G counts, not its stretch: a
!> Reissner-Mindlin section turns with its fibre. A moment along the fibre (drilling) has no
!> angle to work on; the scene refuses it (casca_scene).
module casca_moment_load
  use casca_kinds, only: dp
  use casca_vectors, only: cross
  implicit none
  private
  public :: moment_force, moment_turn

contains

  !> f: the load on G; k = df/dG
  pure subroutine moment_force(m, g, f, k)
    real(dp), intent(in) :: m(3), g(3)
    real(dp), intent(out) :: f(3), k(3, 3)
    real(dp) :: gp(3), s, mg(3)
    integer :: i
    gp = g - dot_product(g, m)*m/dot_product(m, m)
    s = dot_product(gp, gp)
    mg = cross(m, g)
    f = mg/s
    k = reshape([0._dp, m(3), -m(2), -m(3), 0._dp, m(1), m(2), -m(1), 0._dp], [3, 3])
    do i = 1, 3
      k(:, i) = (k(:, i) - 2*mg*gp(i)/s)/s
    end do
  end subroutine moment_force

  !> The angle [rad] G turned about m's axis from ga to gb (less than pi either way): the
  !> moment's work over that turn is |m| times it, exactly
  pure real(dp) function moment_turn(m, ga, gb) result(turn)
    real(dp), intent(in) :: m(3), ga(3), gb(3)
    real(dp) :: e(3), pa(3), pb(3)
    e = m/norm2(m)
    pa = ga - dot_product(ga, e)*e
    pb = gb - dot_product(gb, e)*e
    turn = atan2(dot_product(e, cross(pa, pb)), dot_product(pa, pb))
  end function moment_turn
end module casca_moment_load
