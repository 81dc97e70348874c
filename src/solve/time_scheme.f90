!> The time integration scheme, in one place: Newmark (beta, gamma; the thesis' 1, 1.5 by
!> default) and generalized-alpha (Chung & Hulbert 1993) from the user's rho_inf, as one
!> family. Everything that steps in time (the Newton step, the idle bodies, the impulse
!> accounting) asks this type rather than knowing the formulas.
!>
!> The equation of motion holds at the alpha levels,
!>     M [(1 - alpha_m) a_{n+1} + alpha_m a_n] + f_int(q_af) + C^T Lambda = F,
!>     q_af = (1 - alpha_f) q_{n+1} + alpha_f q_n,
!> with Newmark's relations for q_{n+1}, v_{n+1}; alpha_m = alpha_f = 0 is Newmark. The
!> internal force is taken at the blended configuration q_af (the "midpoint" form, which
!> Erlicher, Bonaventura & Bursi 2002 show second order like the weighted-force form) because
!> it keeps the angular momentum: at rho_inf = 1 (alpha_m = alpha_f = 1/2, beta = 1/4,
!> gamma = 1/2) the scheme is the implicit midpoint rule, and as f_int is the gradient of a
!> rotation-invariant energy and M is isotropic (m (x) I3), the linear and angular momentum
!> of a free body are kept exactly (docs/method.md). The contact multiplier Lambda is one
!> unknown at the alpha level, acting along the rows at q_{n+1}, where the gap is closed.
module casca_time_scheme
  use casca_kinds, only: dp
  use casca_shell_element, only: ndof_node
  implicit none
  private
  public :: scheme_t, newmark_scheme, alpha_scheme

  type :: scheme_t
    real(dp) :: beta = 1.0_dp, gamma = 1.5_dp  !< the thesis' dissipative choice for impact
    real(dp) :: alpha_m = 0, alpha_f = 0       !< 0, 0: Newmark
    real(dp) :: rho_inf = -1                   !< < 0: Newmark (not generalized-alpha)
    real(dp) :: dt = 0
  contains
    procedure :: inertia
    procedure :: predictor
    procedure :: uses_acceleration
    procedure :: drops_released
    procedure :: update
    procedure :: moved_start
    procedure :: moved_share
    procedure :: end_force_weight
    procedure :: error_coefficient
    procedure :: describe
  end type scheme_t

contains

  pure function newmark_scheme(beta, gamma) result(s)
    real(dp), intent(in) :: beta, gamma
    type(scheme_t) :: s
    s%beta = beta; s%gamma = gamma
  end function newmark_scheme

  !> Chung & Hulbert's optimal parameters for the spectral radius rho_inf at infinite
  !> frequency (0 <= rho_inf <= 1): second order, high frequencies damped to rho_inf
  pure function alpha_scheme(rho_inf) result(s)
    real(dp), intent(in) :: rho_inf
    type(scheme_t) :: s
    s%rho_inf = rho_inf
    s%alpha_m = (2*rho_inf - 1)/(rho_inf + 1)
    s%alpha_f = rho_inf/(rho_inf + 1)
    s%gamma = 0.5_dp - s%alpha_m + s%alpha_f
    s%beta = 0.25_dp*(1 - s%alpha_m + s%alpha_f)**2
  end function alpha_scheme

  !> The inertia of the residual as cm M q - M qs (casca_assembly): from the step's start
  !> (q, v, a) with a_{n+1} = q_{n+1}/(beta dt^2) - [q/(beta dt^2) + v/(beta dt) + (1/(2 beta) - 1) a]
  pure subroutine inertia(s, q, v, a, cm, qs)
    class(scheme_t), intent(in) :: s
    real(dp), intent(in) :: q(:), v(:), a(:)
    real(dp), intent(out) :: cm, qs(:)
    real(dp) :: b, dt
    b = s%beta; dt = s%dt
    cm = (1 - s%alpha_m)/(b*dt*dt)
    qs = (1 - s%alpha_m)*(q/(b*dt*dt) + v/(b*dt) + (0.5_dp/b - 1)*a) - s%alpha_m*a
  end subroutine inertia

  !> The first iterate: the step with zero new acceleration, q + dt v + (1/2 - beta) dt^2 a,
  !> unless beta > 1/2, where that lies against the motion (the thesis' beta 1: dt^2 a from
  !> the step with the start's acceleration held, q + dt v + dt^2 a/2, which is taken then:
  !> the thesis' two rings took 2,175 Newton iterations and take 1,592). (Held for every
  !> scheme, generalized-alpha's rings took 2,618 instead of 2,579, and the trapezoidal
  !> rule at ten times the thesis' step stalled in test_hard_cases.)
  !> With beta <= 1/2 the fibre and thickness parameters (components 4 to 7 of a node) take
  !> q + dt v only: they carry the through-thickness modes (~1e7 rad/s) that no implicit step
  !> follows and that such a scheme damps little, so their acceleration at the step's start
  !> is large and alternates, and its dt^2 term turned fibres by tens of degrees in the first
  !> iterate (a ring thrown at a wall at 100 m/s: 1,493 Newton iterations in 0.6 ms, now
  !> 1,315; a rigid rotation's fibres still follow dt v). The thickness parameter (7), which
  !> has no mass, is held: its Newmark velocity is no rate of anything (with rho_inf 1 it
  !> alternates and grows), and dt v threw it by 14 where it is 0.3 (a rubber ring thrown
  !> at a floor at 15 m/s: Newton diverged at 2.09 ms, whatever the step).
  !> A scheme whose step does not use a (uses_acceleration: rho_inf 1) predicts q + dt v.
  pure subroutine predictor(s, q, v, a, qp)
    class(scheme_t), intent(in) :: s
    real(dp), intent(in) :: q(:), v(:), a(:)
    real(dp), intent(out) :: qp(:)
    integer :: c
    real(dp) :: w
    w = merge(0.5_dp, 0.5_dp - s%beta, s%beta > 0.5_dp)
    if (.not. s%uses_acceleration()) w = 0
    qp = q + s%dt*v + s%dt*s%dt*w*a
    if (s%beta > 0.5_dp) return
    do c = 4, ndof_node - 1
      qp(c::ndof_node) = q(c::ndof_node) + s%dt*v(c::ndof_node)
    end do
    qp(ndof_node::ndof_node) = q(ndof_node::ndof_node)
  end subroutine predictor

  !> Whether the step depends on its start acceleration a: its weight in the inertia (qs),
  !> (1 - alpha_m)(1/(2 beta) - 1) - alpha_m, is 0 at rho_inf 1 (the implicit midpoint rule,
  !> whose step is q and v alone). There a is a by-product, a_n+1 = 2 (v_n+1 - v_n)/dt - a_n,
  !> whose alternating part nothing damps: a node held on a plane whose velocity alternates by
  !> +-w (a plate's through-thickness mode after its landing) adds 4 w / dt to it each step
  !> (a plate sliding on a plane at dt 1 ms: +-700 m/s^2 at a node after 0.2 s), and the
  !> predictor's dt^2 a / 4 threw such a node, released mid-slide, 1.75e-4 m into the plane.
  elemental logical function uses_acceleration(s)
    class(scheme_t), intent(in) :: s
    uses_acceleration = abs((1 - s%alpha_m)*(0.5_dp/s%beta - 1) - s%alpha_m) > 1e-12_dp
  end function uses_acceleration

  !> Whether a contact released in a step has its force (friction with it) taken out of the
  !> step's start acceleration, which is then taken again (newmark.f90): where what is left
  !> would push, gamma < 1 or generalized-alpha; with gamma >= 1 (the thesis' 1.5) it pulls
  !> back and dissipates, and stays
  elemental logical function drops_released(s)
    class(scheme_t), intent(in) :: s
    drops_released = s%gamma < 1 .or. s%alpha_m /= 0
  end function drops_released

  !> Newmark's relations: the end acceleration and velocity of the step q -> q1 from its
  !> start (q, v, a)
  pure subroutine update(s, q, v, a, q1, v1, a1)
    class(scheme_t), intent(in) :: s
    real(dp), intent(in) :: q(:), v(:), a(:), q1(:)
    real(dp), intent(out) :: v1(:), a1(:)
    real(dp) :: b, dt
    b = s%beta; dt = s%dt
    a1 = (q1 - q - dt*v)/(b*dt*dt) - (0.5_dp/b - 1)*a
    v1 = v + dt*((1 - s%gamma)*a + s%gamma*a1)
  end subroutine update

  !> The start acceleration a of a step of another length than the last one, h_last, whose
  !> own start acceleration was a_last. Generalized-alpha's a_n is the acceleration at
  !> t_n + (alpha_m - alpha_f) dt, not at t_n, so a new length moves that point by
  !> (alpha_m - alpha_f)(dt - h_last), and a is moved along the last step's rate of change.
  !> Kept as it was, the scheme is first order over steps of changing length, and its
  !> spurious mode, stirred at each change, made the error control's energy bound reject
  !> steps (docs/method.md: a soft cantilever at tolerance 1e-7 took 435 steps, now 151).
  !> Newmark's a is at t_n: unchanged.
  pure subroutine moved_start(s, h_last, a_last, a)
    class(scheme_t), intent(in) :: s
    real(dp), intent(in) :: h_last, a_last(:)
    real(dp), intent(inout) :: a(:)
    real(dp) :: k
    k = start_shift(s, h_last)
    if (k /= 0) a = a + k*(a - a_last)
  end subroutine moved_start

  !> A share A of M a (a released contact's force, carried on by the accounting: rows.f90) at
  !> the start of a step of another length than the last one, moved as moved_start moves a.
  !> The last step was free (moved_start acts after free steps only), so the share fell in it
  !> by -alpha_m / (1 - alpha_m), and was -(1 - alpha_m) / alpha_m A at its start. (Left as
  !> it was, a ball's impulse column parted from its momentum by 1.9e-4 of the impulse where
  !> the steps after its bounce were halved.)
  elemental subroutine moved_share(s, h_last, a)
    class(scheme_t), intent(in) :: s
    real(dp), intent(in) :: h_last
    real(dp), intent(inout) :: a
    if (s%alpha_m == 0) return   ! (the share is 0 after a free step)
    a = a*(1 + start_shift(s, h_last)/s%alpha_m)
  end subroutine moved_share

  !> moved_start's factor: (alpha_m - alpha_f)(dt - h_last)/h_last, 0 where nothing moves
  !> (no last step, Newmark, or the same length)
  elemental real(dp) function start_shift(s, h_last) result(k)
    class(scheme_t), intent(in) :: s
    real(dp), intent(in) :: h_last
    k = 0
    if (h_last <= 0 .or. s%alpha_m == s%alpha_f .or. abs(s%dt - h_last) <= 1e-9_dp*s%dt) return
    k = (s%alpha_m - s%alpha_f)*(s%dt - h_last)/h_last
  end function start_shift

  !> A force F acting at the alpha level, with the start's share A of M a, gives the end
  !> acceleration's share (F - alpha_m A)/(1 - alpha_m) (Newmark: F): the impulse accounting's
  !> weights (rows.f90)
  elemental real(dp) function end_force_weight(s, f, a_start) result(w)
    class(scheme_t), intent(in) :: s
    real(dp), intent(in) :: f, a_start
    w = (f - s%alpha_m*a_start)/(1 - s%alpha_m)
  end function end_force_weight

  !> c of the local error estimate c dt^2 |a_{n+1} - a_n| (a length): the position's
  !> (Zienkiewicz & Xie 1991: beta - 1/6, plus (alpha_m - alpha_f)/2 for generalized-alpha,
  !> whose a tracks the physical one at t + (alpha_m - alpha_f) dt), or, when gamma is not the
  !> second-order one (the thesis' 1.5), the velocity's (gamma - 1/2 + alpha_m - alpha_f) dt
  !> |a_{n+1} - a_n| times dt, whichever is larger
  elemental real(dp) function error_coefficient(s) result(c)
    class(scheme_t), intent(in) :: s
    c = max(abs(s%beta - 1/6._dp + 0.5_dp*(s%alpha_m - s%alpha_f)), &
            abs(s%gamma - 0.5_dp + s%alpha_m - s%alpha_f))
  end function error_coefficient

  !> e.g. "generalized-alpha, rho_inf 0.8" or "Newmark beta 1, gamma 1.5"
  function describe(s) result(str)
    class(scheme_t), intent(in) :: s
    character(len=:), allocatable :: str
    character(len=80) :: buf
    if (s%rho_inf >= 0) then
      write (buf, '(a,g0.4,a)') 'generalized-alpha (rho_inf ', s%rho_inf, ')'
    else
      write (buf, '(a,g0.4,a,g0.4)') 'Newmark (beta ', s%beta, ', gamma ', s%gamma
      buf = trim(buf)//')'
    end if
    str = trim(buf)
  end function describe
end module casca_time_scheme
