!> Shape functions, quadrature and the shell element against independent answers:
!> partition of unity, Kronecker property, finite differences, rigid-motion invariance.
program test_element
  use casca_kinds, only: dp, pi
  use casca_error, only: error_t
  use casca_shape_tri10, only: tri10_shape, tri10_node_xi
  use casca_shell_element, only: shell_rule_t, shell_rule_init, shell_reference, &
                                 shell_energy_force, shell_mass, svk_lame, shell_stress, von_mises
  use casca_vectors, only: cross
  use casca_check, only: check_le, check_close, check_true, check_summary
  implicit none

  type(shell_rule_t) :: rule
  type(error_t), allocatable :: err
  real(dp) :: x0(3, 10), v0(3, 10), q(7, 10), qp(7, 10), f(70), fp(70), fm(70), k(70, 70)
  real(dp) :: kdum(70, 70), kfd(70, 70), ffd(70), up, um, u, h, lam, mu, detmin, scale
  real(dp), allocatable :: binv(:, :, :), wdet(:)
  real(dp) :: phi(10), dphi(10, 2), php(10), phm(10), dd(10, 2), eps, err_max, r(3, 3), t(3)
  real(dp) :: eig(70), work(1000), m(20, 20), area
  integer :: i, j, l, c, info, nzero, nrule(2, 3), comp, node

  ! --- shape functions
  err_max = 0
  do l = 1, 10
    call tri10_shape(tri10_node_xi(1, l), tri10_node_xi(2, l), phi, dphi)
    do i = 1, 10
      err_max = max(err_max, abs(phi(i) - merge(1._dp, 0._dp, i == l)))
    end do
  end do
  call check_le('shape: Kronecker property at the 10 nodes', err_max, 1e-14_dp)
  err_max = 0
  do i = 1, 50
    call random_number(t(1:2)); t(1:2) = t(1:2)*[1._dp, 1._dp - t(1)]
    call tri10_shape(t(1), t(2), phi, dphi)
    err_max = max(err_max, abs(sum(phi) - 1), maxval(abs(sum(dphi, dim=1))))
    eps = 1e-6_dp
    do j = 1, 2
      if (j == 1) then
        call tri10_shape(t(1) + eps, t(2), php, dd); call tri10_shape(t(1) - eps, t(2), phm, dd)
      else
        call tri10_shape(t(1), t(2) + eps, php, dd); call tri10_shape(t(1), t(2) - eps, phm, dd)
      end if
      up = maxval(abs((php - phm)/(2*eps) - dphi(:, j)))
      if (up > 1e-8_dp) err_max = max(err_max, up)
    end do
  end do
  call check_le('shape: partition of unity and FD derivatives (50 points)', err_max, 1e-8_dp)

  ! --- quadrature: area of the reference triangle and exact monomials
  call shell_rule_init(12, 3, rule, err)
  call check_close('quadrature 12-pt: integral of xi1^3 xi2^3 = 3!3!/8!', quad_mono(12, 3, 3), &
                   36._dp/40320, 1e-12_dp)
  call check_close('quadrature 7-pt: integral of xi1^4 xi2 = 4!1!/7!', quad_mono(7, 4, 1), &
                   24._dp/5040, 1e-12_dp)

  ! --- a curved, distorted element on a sphere of radius 1.3
  call geometry(x0, v0)
  h = 0.1_dp
  call svk_lame(1._dp, 0.3_dp, lam, mu)
  nrule = reshape([7, 2, 7, 3, 12, 3], [2, 3])
  do c = 1, 3
    call shell_rule_init(nrule(1, c), nrule(2, c), rule, err)
    if (allocated(binv)) deallocate (binv, wdet)
    allocate (binv(3, 3, rule%np), wdet(rule%np))
    call shell_reference(rule, x0, v0, h, binv, wdet, detmin)
    call check_true('reference element not inverted', detmin > 0)

    ! deformed state with non-zero thickness parameter
    call random_seed_fixed()
    call random_number(qp)
    q(1:3, :) = x0 + 0.08_dp*(qp(1:3, :) - 0.5_dp)
    q(4:6, :) = v0 + 0.2_dp*(qp(4:6, :) - 0.5_dp)
    q(7, :) = 0.05_dp*(qp(7, :) - 0.5_dp)
    call shell_energy_force(rule, h, lam, mu, binv, wdet, q, .true., u, f, k)
    eps = 1e-6_dp
    do i = 1, 70
      comp = mod(i - 1, 7) + 1; node = (i - 1)/7 + 1
      qp = q; qp(comp, node) = qp(comp, node) + eps
      call shell_energy_force(rule, h, lam, mu, binv, wdet, qp, .false., up, fp, kdum)
      qp = q; qp(comp, node) = qp(comp, node) - eps
      call shell_energy_force(rule, h, lam, mu, binv, wdet, qp, .false., um, fm, kdum)
      ffd(i) = (up - um)/(2*eps)
      kfd(:, i) = (fp - fm)/(2*eps)
    end do
    call check_le('force = FD gradient of energy (rel), rule '//rname(c), &
                  norm2(f - ffd)/norm2(f), 1e-6_dp)
    call check_le('Hessian = FD Jacobian of force (rel), rule '//rname(c), &
                  norm2(k - kfd)/norm2(k), 1e-6_dp)
    call check_le('Hessian symmetric (rel), rule '//rname(c), &
                  norm2(k - transpose(k))/norm2(k), 1e-13_dp)

    ! rigid rotation + translation of the reference state: zero energy and force
    r = rotation([0.3_dp, -0.5_dp, 0.8_dp], 1.1_dp); t = [0.7_dp, -2._dp, 3._dp]
    do l = 1, 10
      q(1:3, l) = matmul(r, x0(:, l)) + t
      q(4:6, l) = matmul(r, v0(:, l))
    end do
    q(7, :) = 0
    call shell_energy_force(rule, h, lam, mu, binv, wdet, q, .false., u, f, kdum)
    area = sum(wdet)/h   ! det(A0) carries h/2, the thickness rule spans 2: sum(wdet) = h area
    scale = 1._dp*h*area   ! E * volume with E = 1
    call check_le('rigid motion: |U| / (E V), rule '//rname(c), abs(u)/scale, 1e-10_dp)
    call check_le('rigid motion: |f| / (E h sqrt(area)), rule '//rname(c), &
                  norm2(f)/(h*sqrt(area)), 1e-10_dp)

    ! free element in its reference state: exactly six zero eigenvalues
    q(1:3, :) = x0; q(4:6, :) = v0; q(7, :) = 0
    call shell_energy_force(rule, h, lam, mu, binv, wdet, q, .true., u, f, k)
    call dsyev('N', 'U', 70, k, 70, eig, work, size(work), info)
    nzero = count(abs(eig) < 1e-8_dp*maxval(abs(eig)))
    print '(a,a,i0,a,es10.3)', rule_label(c), ' zero eigenvalues: ', nzero, &
      ', smallest non-zero / largest: ', eig(7)/eig(70)
    ! 7x2 is shown for the record: its 7th zero mode is why casca integrates with 7x3
    if (c > 1) call check_true('free element Hessian has exactly 6 zero eigenvalues, rule ' &
                               //rname(c), info == 0 .and. nzero == 6 .and. &
                               minval(eig) > -1e-8_dp*maxval(eig))
  end do

  ! mass: total mass = rho * h * area of the curved mid-surface (to quadrature accuracy)
  call shell_mass(rule, x0, v0, h, 7700._dp, m)
  call check_close('mass: total translational mass = rho h area', sum(m(1:10, 1:10)), &
                   7700._dp*h*area, 1e-6_dp)

  ! stress: y = M X (Y = M x0, G = M v0, A = 0) makes F = M at every point of the curved
  ! element, top to bottom, so sigma = M S M^T / det M with S the SVK stress of (M^T M - I)/2
  call stress_of_homogeneous_deformation()
  call check_close('von Mises of uniaxial stress diag(-3, 0, 0) = 3', &
                   von_mises(reshape([-3._dp, 0._dp, 0._dp, 0._dp, 0._dp, 0._dp, 0._dp, 0._dp, &
                                      0._dp], [3, 3])), 3._dp, 1e-14_dp)
  call check_close('von Mises of pure shear tau = 2: sqrt(3) tau', &
                   von_mises(reshape([0._dp, 2._dp, 0._dp, 2._dp, 0._dp, 0._dp, 0._dp, 0._dp, &
                                      0._dp], [3, 3])), 2*sqrt(3._dp), 1e-14_dp)

  call check_summary()

contains

  subroutine stress_of_homogeneous_deformation()
    real(dp) :: mm(3, 3), ee(3, 3), ss(3, 3), sig_ref(3, 3), sig(3, 3), xi(3), worst, dm
    real(dp), parameter :: eye(3, 3) = reshape([1._dp, 0._dp, 0._dp, 0._dp, 1._dp, 0._dp, 0._dp, 0._dp, &
                                                1._dp], [3, 3])
    real(dp), parameter :: pts(2, 3) = reshape([0.2_dp, 0.1_dp, 0.5_dp, 0.3_dp, 1._dp/3, 1._dp/3], [2, 3])
    integer :: ii, ll
    mm = reshape([1.02_dp, 0.01_dp, -0.03_dp, 0.04_dp, 0.97_dp, 0.02_dp, -0.01_dp, 0.05_dp, 1.03_dp], &
                 [3, 3])
    call svk_lame(1._dp, 0.3_dp, lam, mu)
    ee = 0.5_dp*(matmul(transpose(mm), mm) - eye)
    ss = lam*(ee(1, 1) + ee(2, 2) + ee(3, 3))*eye + 2*mu*ee
    dm = dot_product(mm(:, 1), cross(mm(:, 2), mm(:, 3)))
    sig_ref = matmul(mm, matmul(ss, transpose(mm)))/dm
    do ll = 1, 10
      q(1:3, ll) = matmul(mm, x0(:, ll))
      q(4:6, ll) = matmul(mm, v0(:, ll))
    end do
    q(7, :) = 0
    worst = 0
    do ii = 1, 9   ! three area points, each on the bottom, mid and top surfaces
      xi = [pts(:, 1 + (ii - 1)/3), real(mod(ii - 1, 3) - 1, dp)]
      sig = shell_stress(x0, v0, h, lam, mu, q, xi(1), xi(2), xi(3))
      worst = max(worst, maxval(abs(sig - sig_ref))/maxval(abs(sig_ref)))
    end do
    call check_le('stress of y = M X at 3 points x (bottom, mid, top) = M S M^T / det M (rel)', &
                  worst, 1e-12_dp)
  end subroutine stress_of_homogeneous_deformation

  character(len=8) function rname(ic)
    integer, intent(in) :: ic
    write (rname, '(i0,"x",i0)') nrule(1, ic), nrule(2, ic)
  end function rname

  character(len=16) function rule_label(ic)
    integer, intent(in) :: ic
    rule_label = 'rule '//rname(ic)
  end function rule_label

  real(dp) function quad_mono(n, a, b)
    integer, intent(in) :: n, a, b
    type(shell_rule_t) :: rr
    type(error_t), allocatable :: e
    real(dp), allocatable :: xi(:, :), w(:)
    call shell_rule_init(n, 1, rr, e)
    ! recover the points from the shape functions: xi1 = phi of node 2 ... use the rule module
    block
      use casca_quadrature, only: triangle_rule
      call triangle_rule(n, xi, w, e)
    end block
    quad_mono = sum(w*xi(1, :)**a*xi(2, :)**b)
  end function quad_mono

  subroutine random_seed_fixed()
    integer :: ns
    integer, allocatable :: seed(:)
    call random_seed(size=ns)
    allocate (seed(ns)); seed = 12345
    call random_seed(put=seed)
  end subroutine random_seed_fixed

  !> Rodrigues rotation about axis by angle.
  function rotation(axis, angle) result(rr)
    real(dp), intent(in) :: axis(3), angle
    real(dp) :: rr(3, 3), n(3), kx(3, 3)
    integer :: ii
    n = axis/norm2(axis)
    kx = reshape([0._dp, n(3), -n(2), -n(3), 0._dp, n(1), n(2), -n(1), 0._dp], [3, 3])
    rr = sin(angle)*kx + (1 - cos(angle))*matmul(kx, kx)
    do ii = 1, 3
      rr(ii, ii) = rr(ii, ii) + 1
    end do
  end function rotation

  !> Nodes of a distorted cubic patch lifted onto a sphere; exact normals.
  subroutine geometry(x, v)
    real(dp), intent(out) :: x(3, 10), v(3, 10)
    real(dp) :: uv(2), p(3)
    integer :: ll
    do ll = 1, 10
      uv = [0.5_dp*tri10_node_xi(1, ll) + 0.1_dp*tri10_node_xi(2, ll), &
            0.15_dp*tri10_node_xi(1, ll) + 0.6_dp*tri10_node_xi(2, ll)]
      uv = uv + 0.03_dp*[sin(7._dp*ll), cos(5._dp*ll)]   ! distortion
      p = [uv(1), uv(2), 1._dp]
      v(:, ll) = p/norm2(p)
      x(:, ll) = 1.3_dp*v(:, ll)
    end do
  end subroutine geometry
end program test_element
