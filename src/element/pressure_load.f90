!> A follower pressure p on the mid-surface of one 10-node element, at its current positions
!> Y (the fibres and thickness parameter take no share):
!>
!>   f_l = p * integral of phi_l (y,1 x y,2) dxi1 dxi2,      y = phi_l Y^l
!>
!> p > 0 pushes along y,1 x y,2, the side the element's node order (and so its fibres) points
!> to: on a closed surface whose normals point outwards it is an internal pressure. Its
!> derivative, the load stiffness, follows from d(y,1 x y,2) = phi_j,1 dY^j x y,2 +
!> y,1 x phi_j,2 dY^j. The integrals use the element's area rule (casca_model's rule), the
!> one the strain energy uses.
module casca_pressure_load
  use casca_kinds, only: dp
  use casca_shell_element, only: shell_rule_t
  use casca_vectors, only: cross
  implicit none
  private
  public :: pressure_force, pressure_volume

contains

  !> f(:, l): the force on node l's position; with want_k, k(a, l, b, j) = d f(a, l) / d Y(b, j)
  !> (unsymmetric; k is not touched without want_k).
  pure subroutine pressure_force(rule, p, y, want_k, f, k)
    type(shell_rule_t), intent(in) :: rule
    real(dp), intent(in) :: p, y(3, 10)
    logical, intent(in) :: want_k
    real(dp), intent(out) :: f(3, 10), k(3, 10, 3, 10)
    real(dp) :: y1(3), y2(3), n(3), w, s1(3, 3), s2(3, 3)
    integer :: ia, l, j

    f = 0
    if (want_k) k = 0
    do ia = 1, rule%na
      y1 = matmul(y, rule%dphi(:, 1, ia)); y2 = matmul(y, rule%dphi(:, 2, ia))
      n = cross(y1, y2)
      w = p*rule%wa(ia)
      do l = 1, 10
        f(:, l) = f(:, l) + (w*rule%phi(l, ia))*n
      end do
      if (.not. want_k) cycle
      ! dn/dY^j = phi_j,2 [y,1]x - phi_j,1 [y,2]x, with [a]x b = a x b
      s1 = skew(y1); s2 = skew(y2)
      do j = 1, 10
        do l = 1, 10
          k(:, l, :, j) = k(:, l, :, j) + (w*rule%phi(l, ia))* &
                          (rule%dphi(j, 2, ia)*s1 - rule%dphi(j, 1, ia)*s2)
        end do
      end do
    end do
  end subroutine pressure_force

  !> (1/3) integral of y . (y,1 x y,2) dxi1 dxi2: summed over a closed surface (normals
  !> outwards) the enclosed volume, whose change times p is the pressure's work; over an
  !> open surface whose boundary is held, its change is the volume swept.
  pure real(dp) function pressure_volume(rule, y) result(v)
    type(shell_rule_t), intent(in) :: rule
    real(dp), intent(in) :: y(3, 10)
    integer :: ia
    v = 0
    do ia = 1, rule%na
      v = v + rule%wa(ia)*dot_product(matmul(y, rule%phi(:, ia)), &
                                      cross(matmul(y, rule%dphi(:, 1, ia)), &
                                            matmul(y, rule%dphi(:, 2, ia))))
    end do
    v = v/3
  end function pressure_volume

  !> [a]x: the matrix of b -> a x b
  pure function skew(a) result(s)
    real(dp), intent(in) :: a(3)
    real(dp) :: s(3, 3)
    s = reshape([0._dp, a(3), -a(2), -a(3), 0._dp, a(1), a(2), -a(1), 0._dp], [3, 3])
  end function skew
end module casca_pressure_load
