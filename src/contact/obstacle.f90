!> Rigid obstacles given by a few numbers: a plane, a sphere or a cylinder (infinite), fixed or
!> translating at a prescribed velocity. A node meets an obstacle at its closest point; the
!> normal points to the side the bodies are on, so the signed distance is the gap of the
!> mid-surface (the face offset is added by the caller).
module casca_obstacle
  use casca_kinds, only: dp
  implicit none
  private
  public :: obstacle_t, obstacle_point, obstacle_ray_time, unit_across

  type :: obstacle_t
    character(len=64) :: name = ''
    character(len=16) :: shape = 'plane'
    real(dp) :: point(3) = 0      !< plane: a point of it; sphere: centre; cylinder: a point of the axis
    real(dp) :: normal(3) = 0     !< plane: unit normal towards the bodies; cylinder: unit axis
    real(dp) :: radius = 0
    logical :: inside = .false.   !< sphere, cylinder: the bodies are inside (a container)
    real(dp) :: velocity(3) = 0   !< prescribed translation [m/s]
  end type obstacle_t

contains

  !> At time t: the unit normal n at the point of the obstacle closest to x (towards the
  !> bodies' side) and the signed distance d of x from it (negative: x is in the obstacle).
  pure subroutine obstacle_point(ob, t, x, n, d)
    type(obstacle_t), intent(in) :: ob
    real(dp), intent(in) :: t, x(3)
    real(dp), intent(out) :: n(3), d
    real(dp) :: c(3), r(3), rn
    c = ob%point + t*ob%velocity
    select case (ob%shape)
    case ('plane')
      n = ob%normal
      d = dot_product(x - c, n)
      return
    case ('sphere')
      r = x - c
    case default   ! cylinder: the part of x - c across the axis
      r = (x - c) - dot_product(x - c, ob%normal)*ob%normal
    end select
    rn = norm2(r)
    if (rn > 0) then
      n = r/rn
    else   ! on the centre or the axis: any direction across
      n = [1, 0, 0]
      if (ob%shape == 'cylinder') n = unit_across(ob%normal)
    end if
    d = rn - ob%radius
    if (ob%inside) then
      n = -n; d = -d
    end if
  end subroutine obstacle_point

  !> The first time t >= 0 at which a point at x moving at w relative to a sphere or a
  !> cylinder comes within off of its wall (0 if it is within already); -1 if it never does.
  !> A path aimed past the centre meets the wall later than its distance over the closing
  !> speed says (a ball inside a spherical shell: 21.3 ms for 18.6); a plane's is that ratio.
  pure real(dp) function obstacle_ray_time(ob, x, w, off) result(t)
    type(obstacle_t), intent(in) :: ob
    real(dp), intent(in) :: x(3), w(3), off
    real(dp) :: r(3), u(3), rho, a, b, disc
    t = -1
    r = x - ob%point; u = w
    if (ob%shape == 'cylinder') then   ! (across the axis)
      r = r - dot_product(r, ob%normal)*ob%normal; u = u - dot_product(u, ob%normal)*ob%normal
    end if
    rho = ob%radius + merge(-off, off, ob%inside)   ! |r + u t| = rho at the face
    if (merge(dot_product(r, r) >= rho**2, dot_product(r, r) <= rho**2, ob%inside)) then
      t = 0; return
    end if
    a = dot_product(u, u); b = dot_product(r, u)
    if (a <= 0) return
    disc = b*b - a*(dot_product(r, r) - rho**2)
    if (disc < 0) return   ! (outside, passing by)
    if (ob%inside) then
      t = (-b + sqrt(disc))/a   ! (leaving the inner ball)
    else if (b < 0) then
      t = (-b - sqrt(disc))/a
    end if
  end function obstacle_ray_time

  !> A unit vector across the unit vector a (dot_product(u, a) = 0 exactly)
  pure function unit_across(a) result(u)
    real(dp), intent(in) :: a(3)
    real(dp) :: u(3)
    u = [a(2), -a(1), 0._dp]
    if (norm2(u) < 0.5_dp) u = [0._dp, a(3), -a(2)]
    u = u/norm2(u)
  end function unit_across
end module casca_obstacle
