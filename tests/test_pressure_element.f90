!> The follower-pressure kernel (casca_pressure_load) against independent answers, with the
!> element's own area rule:
!> - a curved, distorted element at a perturbed state: the load stiffness equals the central
!>   finite differences of the force (relative 1e-6; the force is quadratic in Y, so the
!>   differences are exact up to round-off);
!> - a flat element: the total force is p * area * unit normal (relative 1e-13), shared as the
!>   integrals of the cubic shape functions, area/30 at a vertex, 3 area/40 at an edge node,
!>   9 area/20 at the centre (relative 1e-13);
!> - a closed tetrahedron of four flat elements (normals outwards), where the rule integrates
!>   every term exactly: the summed volume terms give the tetrahedron's volume |det|/6
!>   (relative 1e-13), the forces sum to zero (1e-13 of p * area), the assembled load
!>   stiffness is symmetric (its skew part <= 1e-13 of it: the element skew parts cancel), and
!>   the force is p times the central-difference gradient of the volume (relative 1e-8: the
!>   pressure is conservative, so p (V - V0) is its work).
program test_pressure_element
  use casca_kinds, only: dp
  use casca_error, only: error_t
  use casca_shape_tri10, only: tri10_node_xi
  use casca_shell_element, only: shell_rule_t, shell_rule_init
  use casca_model, only: area_points, thick_points
  use casca_pressure_load, only: pressure_force, pressure_volume
  use casca_vectors, only: cross
  use casca_check, only: check_le, check_close, check_summary
  implicit none

  real(dp), parameter :: p = 2.5e5_dp
  type(shell_rule_t) :: rule
  type(error_t), allocatable :: err
  real(dp) :: y(3, 10), yp(3, 10), f(3, 10), fp(3, 10), fm(3, 10), k(3, 10, 3, 10)
  real(dp) :: kfd(3, 10, 3, 10), kdum(3, 10, 3, 10), a(3), b(3), c(3), nrm(3), area, eps
  real(dp) :: share(10), pert(3, 10)
  real(dp) :: v(3, 4), xt(3, 20), ft(3, 20), kt(60, 60), vol, gradv(3, 20), xp(3, 20)
  integer :: i, j, l, m, face(3, 4), gl(10, 4)

  call shell_rule_init(area_points, thick_points, rule, err)
  if (allocated(err)) error stop 'rule'

  ! --- curved, distorted element at a perturbed state: K = FD Jacobian of f
  call sphere_patch(y)
  pert = reshape([(sin(1.7_dp*i), i=1, 30)], [3, 10])   ! (a fixed, irregular perturbation)
  y = y + 0.025_dp*pert
  call pressure_force(rule, p, y, .true., f, k)
  eps = 1e-6_dp
  do j = 1, 10
    do i = 1, 3
      yp = y; yp(i, j) = yp(i, j) + eps
      call pressure_force(rule, p, yp, .false., fp, kdum)
      yp = y; yp(i, j) = yp(i, j) - eps
      call pressure_force(rule, p, yp, .false., fm, kdum)
      kfd(:, :, i, j) = (fp - fm)/(2*eps)
    end do
  end do
  call check_le('curved element: load stiffness = FD Jacobian of the force (rel)', &
                norm2(reshape(k - kfd, [900]))/norm2(reshape(k, [900])), 1e-6_dp)

  ! --- flat element: total p * area * n, shares of the cubic shape functions
  a = [0.2_dp, -0.1_dp, 0.3_dp]; b = [1.4_dp, 0.3_dp, -0.2_dp]; c = [0.1_dp, 0.9_dp, 0.5_dp]
  call flat(a, b, c, y)
  nrm = cross(b - a, c - a)
  area = norm2(nrm)/2
  nrm = nrm/norm2(nrm)
  call pressure_force(rule, p, y, .false., f, kdum)
  call check_le('flat element: |sum f - p area n| / (p area)', &
                norm2(sum(f, dim=2) - p*area*nrm)/(p*area), 1e-13_dp)
  share = [1._dp/30, 1._dp/30, 1._dp/30, 3._dp/40, 3._dp/40, 3._dp/40, 3._dp/40, 3._dp/40, &
           3._dp/40, 9._dp/20]
  call check_le('flat element: f_l / (p area n) = 1/30, 3/40, 9/20 (max error)', &
                maxval([(norm2(f(:, l) - share(l)*p*area*nrm), l=1, 10)])/(p*area), 1e-13_dp)

  ! --- closed tetrahedron of four flat elements, normals outwards
  v = reshape([0.1_dp, 0._dp, -0.2_dp, 1.2_dp, 0.1_dp, 0._dp, 0.2_dp, 0.9_dp, 0.1_dp, &
               0.3_dp, 0.2_dp, 1.1_dp], [3, 4])
  face = reshape([1, 3, 2, 1, 2, 4, 1, 4, 3, 2, 3, 4], [3, 4])
  call tetrahedron(v, face, xt, gl, m)
  vol = abs(det3(v(:, 2) - v(:, 1), v(:, 3) - v(:, 1), v(:, 4) - v(:, 1)))/6
  call check_close('tetrahedron: sum of volume terms = |det|/6', total_volume(xt), vol, 1e-13_dp)
  call assemble_tet(xt, ft, kt)
  area = 0
  do l = 1, 4
    area = area + norm2(cross(v(:, face(2, l)) - v(:, face(1, l)), v(:, face(3, l)) - v(:, face(1, l))))/2
  end do
  call check_le('tetrahedron: |sum f| / (p area)', norm2(sum(ft(:, 1:m), dim=2))/(p*area), 1e-13_dp)
  call check_le('tetrahedron: assembled load stiffness skew part (max, rel)', &
                maxval(abs(kt(1:3*m, 1:3*m) - transpose(kt(1:3*m, 1:3*m))))/maxval(abs(kt)), 1e-13_dp)
  eps = 1e-5_dp
  do j = 1, m
    do i = 1, 3
      xp = xt; xp(i, j) = xp(i, j) + eps
      gradv(i, j) = total_volume(xp)
      xp = xt; xp(i, j) = xp(i, j) - eps
      gradv(i, j) = (gradv(i, j) - total_volume(xp))/(2*eps)
    end do
  end do
  call check_le('tetrahedron: |f - p grad V| / |f| (central differences)', &
                norm2(ft(:, 1:m) - p*gradv(:, 1:m))/norm2(ft(:, 1:m)), 1e-8_dp)

  call check_summary()

contains

  !> the 10 nodes of the flat cubic triangle with vertices a, b, c (node order of casca_mesh)
  subroutine flat(a, b, c, x)
    real(dp), intent(in) :: a(3), b(3), c(3)
    real(dp), intent(out) :: x(3, 10)
    integer :: ll
    do ll = 1, 10
      x(:, ll) = a + tri10_node_xi(1, ll)*(b - a) + tri10_node_xi(2, ll)*(c - a)
    end do
  end subroutine flat

  !> xt(:, 1:m): the distinct nodes of the four faces; gl(l, f): node l of face f in xt
  subroutine tetrahedron(v, face, xt, gl, m)
    real(dp), intent(in) :: v(3, 4)
    integer, intent(in) :: face(3, 4)
    real(dp), intent(out) :: xt(3, 20)
    integer, intent(out) :: gl(10, 4), m
    real(dp) :: x(3, 10)
    integer :: ff, ll, n
    m = 0
    do ff = 1, 4
      call flat(v(:, face(1, ff)), v(:, face(2, ff)), v(:, face(3, ff)), x)
      do ll = 1, 10
        gl(ll, ff) = 0
        do n = 1, m
          if (norm2(xt(:, n) - x(:, ll)) < 1e-12_dp) gl(ll, ff) = n
        end do
        if (gl(ll, ff) == 0) then
          m = m + 1; xt(:, m) = x(:, ll); gl(ll, ff) = m
        end if
      end do
    end do
  end subroutine tetrahedron

  real(dp) function total_volume(x)
    real(dp), intent(in) :: x(3, 20)
    integer :: ff
    total_volume = 0
    do ff = 1, 4
      total_volume = total_volume + pressure_volume(rule, x(:, gl(:, ff)))
    end do
  end function total_volume

  !> force and load stiffness summed over the four faces (3 (node - 1) + component)
  subroutine assemble_tet(x, ft, kt)
    real(dp), intent(in) :: x(3, 20)
    real(dp), intent(out) :: ft(3, 20), kt(60, 60)
    real(dp) :: fe(3, 10), ke(3, 10, 3, 10)
    integer :: ff, ll, jj, ii, cc
    ft = 0; kt = 0
    do ff = 1, 4
      call pressure_force(rule, p, x(:, gl(:, ff)), .true., fe, ke)
      ft(:, gl(:, ff)) = ft(:, gl(:, ff)) + fe
      do jj = 1, 10
        do ll = 1, 10
          do cc = 1, 3
            do ii = 1, 3
              kt(3*(gl(ll, ff) - 1) + ii, 3*(gl(jj, ff) - 1) + cc) = &
                kt(3*(gl(ll, ff) - 1) + ii, 3*(gl(jj, ff) - 1) + cc) + ke(ii, ll, cc, jj)
            end do
          end do
        end do
      end do
    end do
  end subroutine assemble_tet

  real(dp) function det3(a, b, c)
    real(dp), intent(in) :: a(3), b(3), c(3)
    det3 = dot_product(a, cross(b, c))
  end function det3

  !> a distorted cubic patch lifted onto a sphere of radius 1.3 (as in test_element)
  subroutine sphere_patch(x)
    real(dp), intent(out) :: x(3, 10)
    real(dp) :: uv(2), q(3)
    integer :: ll
    do ll = 1, 10
      uv = [0.5_dp*tri10_node_xi(1, ll) + 0.1_dp*tri10_node_xi(2, ll), &
            0.15_dp*tri10_node_xi(1, ll) + 0.6_dp*tri10_node_xi(2, ll)]
      uv = uv + 0.03_dp*[sin(7._dp*ll), cos(5._dp*ll)]
      q = [uv(1), uv(2), 1._dp]
      x(:, ll) = 1.3_dp*q/norm2(q)
    end do
  end subroutine sphere_patch
end program test_pressure_element
