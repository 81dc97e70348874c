!> The moment kernel (casca_moment_load) against independent answers:
!> - moment_turn: a fibre turned by a known angle about the moment's axis, stretched and with
!>   a part along the axis, gives that angle (1e-14 rad), both ways round, and past pi/2;
!> - the load is the gradient of the potential -|m| theta (theta summed by moment_turn from a
!>   fixed start, central differences: relative 1e-8), with theta's own definition;
!> - the load stiffness equals the central differences of the load (relative 1e-7) and is
!>   symmetric (1e-13 of it), as a potential's Hessian must be;
!> - for a fibre across the axis the fibre's torque G x f is the moment itself (1e-14).
program test_moment_load
  use casca_kinds, only: dp
  use casca_moment_load, only: moment_force, moment_turn
  use casca_vectors, only: cross
  use casca_check, only: check_le, check_summary
  implicit none
  real(dp) :: m(3), e(3), a(3), b(3), g0(3), g(3), gp(3), f(3), k(3, 3), kfd(3, 3), fd(3), fp(3), fm(3)
  real(dp) :: kd(3, 3), eps, t
  real(dp), parameter :: turns(3) = [0.7_dp, -2.1_dp, 3.0_dp]
  integer :: i

  m = [0.3_dp, -1.2_dp, 0.5_dp]
  e = m/norm2(m)
  a = cross(e, [1._dp, 0._dp, 0._dp]); a = a/norm2(a)   ! (a, b: across the axis)
  b = cross(e, a)
  ! a fibre 1.3 long, 0.4 of it along the axis, turned by t from a
  do i = 1, 3
    t = turns(i)
    g0 = 1.3_dp*(a + 0.4_dp*e)
    g = 1.1_dp*(cos(t)*a + sin(t)*b) + 0.9_dp*e   ! (stretched, another part along e)
    call check_le('moment_turn: a fibre turned by a known angle (rad)', abs(moment_turn(m, g0, g) - t), 1e-14_dp)
    call check_le('moment_turn: back again (rad)', abs(moment_turn(m, g, g0) + t), 1e-14_dp)
  end do

  ! a fibre in a general position: the load is the gradient of |m| theta
  g0 = a
  g = [0.4_dp, 0.8_dp, -0.3_dp]
  call moment_force(m, g, f, k)
  eps = 1e-6_dp
  do i = 1, 3
    gp = g; gp(i) = gp(i) + eps
    fd(i) = norm2(m)*moment_turn(m, g0, gp)
    call moment_force(m, gp, fp, kd)
    gp = g; gp(i) = gp(i) - eps
    fd(i) = (fd(i) - norm2(m)*moment_turn(m, g0, gp))/(2*eps)
    call moment_force(m, gp, fm, kd)
    kfd(:, i) = (fp - fm)/(2*eps)
  end do
  call check_le('load = gradient of |m| theta (rel)', norm2(f - fd)/norm2(f), 1e-8_dp)
  call check_le('load stiffness = differences of the load (rel)', norm2(k - kfd)/norm2(k), 1e-7_dp)
  call check_le('load stiffness symmetric (rel)', norm2(k - transpose(k))/norm2(k), 1e-13_dp)

  ! a fibre across the axis: its torque is the moment
  g = 0.8_dp*(cos(0.3_dp)*a + sin(0.3_dp)*b)
  call moment_force(m, g, f, k)
  call check_le('fibre across the axis: G x f = m (rel)', norm2(cross(g, f) - m)/norm2(m), 1e-14_dp)
  call check_summary()
end program test_moment_load
