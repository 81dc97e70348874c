!> The time schemes' formulas (casca_time_scheme: the inertia factors, the update and the error
!> coefficient that newmark_step and the step control use) on one degree of freedom,
!> q'' + w^2 q = F, against independent answers:
!> - generalized-alpha from rho_inf (Chung & Hulbert 1993): rho_inf = 1 gives the midpoint
!>   rule's beta 1/4, gamma 1/2, alpha_m = alpha_f = 1/2; rho_inf = 0 gives beta 1, gamma 3/2
!>   (the thesis' values) with alpha_m = -1 (exact to 1e-15);
!> - the spectral radius of the step's amplification matrix at w dt = 1e6 equals rho_inf
!>   (to 1e-3; below 1e-2 for 0), and is 1 for the trapezoidal rule;
!> - the order of the error at t = 10 of q = cos t (w = 1) from dt = 0.1 to 0.05: 2 for
!>   generalized-alpha (rho_inf 0.8 and 0.5) and the trapezoidal rule, 1 for the thesis'
!>   Newmark (each within 0.2);
!> - the local error estimate c dt^2 (a1 - a0) against the true local error of one step of
!>   q'' = 6 t (q = t^3) from exact data at t = 1 (the algorithmic acceleration of
!>   generalized-alpha: 6 (t + (alpha_m - alpha_f) dt)), dt = 1e-3: ratio 1 within 1% for the
!>   trapezoidal rule and generalized-alpha (the Zienkiewicz & Xie estimate is exact for a
!>   linear acceleration);
!> - steps of alternating lengths (2h/3, h/3) on q = cos t: the order of the largest error
!>   over t <= 10 from h = 0.025 to 0.0125 is 2 (within 0.2) for generalized-alpha 0.8 when
!>   each step starts from moved_start's acceleration, and below 1.5 when it does not (a_n is
!>   the acceleration at t_n + (alpha_m - alpha_f) dt: kept as it is across a change of
!>   length, the scheme is first order);
!> - uses_acceleration: one step of q'' + q = 0 from a = 0 and from a = 100 gives the same q1
!>   (to 1e-12) at rho_inf 1 (the midpoint rule) only, and there the predictor is q + dt v.
program test_time_scheme
  use casca_kinds, only: dp
  use casca_time_scheme, only: scheme_t, newmark_scheme, alpha_scheme
  use casca_check, only: check_close, check_le, check_true, check_summary
  implicit none
  type(scheme_t) :: s
  real(dp) :: rho(4) = [0._dp, 0.5_dp, 0.8_dp, 1._dp], e1, e2
  character(len=40) :: name
  integer :: i

  s = alpha_scheme(1._dp)
  call check_close('rho_inf 1: beta = 1/4', s%beta, 0.25_dp, 1e-15_dp)
  call check_close('rho_inf 1: gamma = 1/2', s%gamma, 0.5_dp, 1e-15_dp)
  call check_close('rho_inf 1: alpha_m = 1/2', s%alpha_m, 0.5_dp, 1e-15_dp)
  call check_close('rho_inf 1: alpha_f = 1/2', s%alpha_f, 0.5_dp, 1e-15_dp)
  s = alpha_scheme(0._dp)
  call check_close('rho_inf 0: beta = 1 (the thesis'')', s%beta, 1._dp, 1e-15_dp)
  call check_close('rho_inf 0: gamma = 3/2 (the thesis'')', s%gamma, 1.5_dp, 1e-15_dp)
  call check_close('rho_inf 0: alpha_m = -1', s%alpha_m, -1._dp, 1e-15_dp)

  do i = 1, 4
    write (name, '(a,f3.1)') 'spectral radius, rho_inf ', rho(i)
    if (rho(i) > 0) then
      call check_close(trim(name), radius(alpha_scheme(rho(i)), 1e6_dp), rho(i), 1e-3_dp)
    else
      call check_le(trim(name), radius(alpha_scheme(rho(i)), 1e6_dp), 1e-2_dp)
    end if
  end do
  call check_close('spectral radius, trapezoidal rule', radius(newmark_scheme(0.25_dp, 0.5_dp), 1e6_dp), &
                   1._dp, 1e-3_dp)

  call order_check('order, generalized-alpha rho_inf 0.8', alpha_scheme(0.8_dp), 2._dp)
  call order_check('order, generalized-alpha rho_inf 0.5', alpha_scheme(0.5_dp), 2._dp)
  call order_check('order, trapezoidal rule', newmark_scheme(0.25_dp, 0.5_dp), 2._dp)
  call order_check('order, thesis Newmark (beta 1, gamma 1.5)', newmark_scheme(1._dp, 1.5_dp), 1._dp)

  call estimate_check('error estimate / true local error, trapezoidal', newmark_scheme(0.25_dp, 0.5_dp))
  call estimate_check('error estimate / true local error, rho_inf 0.8', alpha_scheme(0.8_dp))
  call estimate_check('error estimate / true local error, rho_inf 0.5', alpha_scheme(0.5_dp))

  call variable_check(alpha_scheme(0.8_dp), .true., e1)
  call check_close('order, rho_inf 0.8, alternating step lengths, start moved', e1, 2._dp, 0.1_dp)
  call variable_check(alpha_scheme(0.8_dp), .false., e2)
  call check_le('order, rho_inf 0.8, alternating step lengths, start not moved (below 1.5)', e2, 1.5_dp)

  call acceleration_check('rho_inf 1', alpha_scheme(1._dp), .false.)
  call acceleration_check('rho_inf 0.8', alpha_scheme(0.8_dp), .true.)
  call acceleration_check('trapezoidal rule', newmark_scheme(0.25_dp, 0.5_dp), .true.)
  call acceleration_check('thesis Newmark', newmark_scheme(1._dp, 1.5_dp), .true.)
  call check_summary()

contains

  !> one step of q'' + w2 q = f (unit mass) in casca's form: the residual
  !> cm q1 - qs + (1 - alpha_f) w2 q1 + alpha_f w2 q0 - f = 0 solved for q1, then the update
  subroutine step(s, w2, f, x)
    type(scheme_t), intent(in) :: s
    real(dp), intent(in) :: w2, f
    real(dp), intent(inout) :: x(3)   !< q, v, a
    real(dp) :: cm, qs(1), q1(1), v1(1), a1(1)
    call s%inertia(x(1:1), x(2:2), x(3:3), cm, qs)
    q1 = (qs + f - s%alpha_f*w2*x(1))/(cm + (1 - s%alpha_f)*w2)
    call s%update(x(1:1), x(2:2), x(3:3), q1, v1, a1)
    x = [q1(1), v1(1), a1(1)]
  end subroutine step

  !> spectral radius of the step at w dt = wdt: the growth of A^(2^40), A the amplification
  !> matrix of (q, v, a) (its columns: one step from each unit vector), by squaring with
  !> the norms' logarithms kept apart
  real(dp) function radius(s0, wdt)
    type(scheme_t), intent(in) :: s0
    real(dp), intent(in) :: wdt
    type(scheme_t) :: s
    real(dp) :: a(3, 3), logn, nrm
    integer :: j, k
    s = s0; s%dt = 1
    a = 0
    do j = 1, 3
      a(j, j) = 1
      call step(s, wdt**2, 0._dp, a(:, j))
    end do
    logn = 0
    do k = 1, 40
      a = matmul(a, a)
      nrm = maxval(abs(a))
      a = a/nrm
      logn = logn + log(nrm)/2._dp**k
    end do
    radius = exp(logn)
  end function radius

  !> |q(10) - cos 10| at dt and dt/2 from exact start data: the observed order
  subroutine order_check(label, s0, expected)
    character(len=*), intent(in) :: label
    type(scheme_t), intent(in) :: s0
    real(dp), intent(in) :: expected
    real(dp) :: err(2), x(3)
    type(scheme_t) :: s
    integer :: k, j
    s = s0
    do j = 1, 2
      s%dt = 0.1_dp/j
      x = [1._dp, 0._dp, -1._dp]
      do k = 1, 100*j
        call step(s, 1._dp, 0._dp, x)
      end do
      err(j) = abs(x(1) - cos(10._dp))
    end do
    call check_close(label, log(err(1)/err(2))/log(2._dp), expected, 0.2_dp/expected)
  end subroutine order_check

  !> the observed order of the largest |q - cos t| over t <= 10 from h = 0.025 to 0.0125, the
  !> steps alternating 2h/3 and h/3, each starting from moved_start's acceleration (moved) or
  !> from the last step's end acceleration
  subroutine variable_check(s0, moved, order)
    type(scheme_t), intent(in) :: s0
    logical, intent(in) :: moved
    real(dp), intent(out) :: order
    real(dp) :: err(2), x(3), a_last, h_last, a(1), t
    type(scheme_t) :: s
    integer :: k, j
    s = s0
    do j = 1, 2
      x = [1._dp, 0._dp, -1._dp]
      h_last = 0; a_last = 0; t = 0; err(j) = 0
      do k = 1, 800*j
        s%dt = merge(2, 1, mod(k, 2) == 1)*0.025_dp/(3*j)
        a = x(3)
        if (moved) call s%moved_start(h_last, [a_last], a)
        h_last = s%dt; a_last = a(1); x(3) = a(1)
        call step(s, 1._dp, 0._dp, x)
        t = t + s%dt
        err(j) = max(err(j), abs(x(1) - cos(t)))
      end do
    end do
    order = log(err(1)/err(2))/log(2._dp)
  end subroutine variable_check

  !> one step of q'' = 6 t from q = t^3 at t = 1 (the algorithmic acceleration: a at
  !> t + (alpha_m - alpha_f) dt, Arnold & Bruls 2007): estimate c dt^2 (a1 - a0) over the error
  subroutine estimate_check(label, s0)
    character(len=*), intent(in) :: label
    type(scheme_t), intent(in) :: s0
    type(scheme_t) :: s
    real(dp) :: x(3), a0, t, ta
    s = s0; s%dt = 1e-3_dp
    t = 1; x = [1._dp, 3._dp, 6*(t + (s%alpha_m - s%alpha_f)*s%dt)]; a0 = x(3)
    ta = t + (1 - s%alpha_f)*s%dt   ! (the load at the alpha level)
    call step(s, 0._dp, 6*ta, x)
    call check_close(label, s%error_coefficient()*s%dt**2*(x(3) - a0)/(x(1) - (t + s%dt)**3), &
                     1._dp, 1e-2_dp)
  end subroutine estimate_check

  !> uses_acceleration against the step itself: whether one step's q1 changes with the start
  !> acceleration; a scheme whose step does not use it predicts q + dt v
  subroutine acceleration_check(label, s0, uses)
    character(len=*), intent(in) :: label
    type(scheme_t), intent(in) :: s0
    logical, intent(in) :: uses
    type(scheme_t) :: s
    real(dp) :: x(3), y(3), qp(1)
    s = s0; s%dt = 0.1_dp
    x = [1._dp, 0.5_dp, 0._dp]; y = [1._dp, 0.5_dp, 100._dp]
    call step(s, 1._dp, 0._dp, x)
    call step(s, 1._dp, 0._dp, y)
    call check_true(label//': the step depends on the start acceleration, as uses_acceleration says', &
                    ((abs(x(1) - y(1)) > 1e-12_dp) .eqv. uses) .and. (s%uses_acceleration() .eqv. uses))
    if (uses) return
    call s%predictor([1._dp], [0.5_dp], [100._dp], qp)
    call check_close(label//': predictor q + dt v', qp(1), 1.05_dp, 1e-15_dp)
  end subroutine acceleration_check
end program test_time_scheme
