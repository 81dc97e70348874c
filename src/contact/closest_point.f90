!> Closest point of a linear triangle to a point: the per-pair kernel of contact detection
!> (formulation.md, section 3). The thesis projects on the plane, keeps the foot if it is
!> inside, and otherwise takes the nearest of the three clamped edges (a clamp at an end is
!> the vertex). The Voronoi-region walk of Ericson ("Real-Time Collision Detection",
!> ClosestPtPointTriangle) gives the same point with a handful of dot products and no square
!> root, so it is used here; zero-area triangles fall back to the three segments.
module casca_closest_point
  use casca_kinds, only: dp
  implicit none
  private
  public :: closest_point_triangle
  public :: region_face, region_edge_ab, region_edge_bc, region_edge_ca
  public :: region_vertex_a, region_vertex_b, region_vertex_c

  !> Where the closest point lies: the open face, an edge (1: a-b, 2: b-c, 3: c-a) or a vertex.
  integer, parameter :: region_face = 0
  integer, parameter :: region_edge_ab = 1, region_edge_bc = 2, region_edge_ca = 3
  integer, parameter :: region_vertex_a = 4, region_vertex_b = 5, region_vertex_c = 6

  !> A triangle whose smallest height is below sqrt(eps) times its longest edge is handled as
  !> its three segments: the plane (and the normal equations behind the face formula) is then
  !> ill-conditioned, while the segment answer is off by at most that height.
  real(dp), parameter :: thin_ratio2 = 1.0e-16_dp   ! (h_min / l_max)**2

contains

  !> q = closest point of triangle (a, b, c) to p, q = bary(1) a + bary(2) b + bary(3) c with
  !> bary >= 0 summing to 1, and the region (region_* constants) q lies in.
  pure subroutine closest_point_triangle(p, a, b, c, q, bary, region)
    real(dp), intent(in) :: p(3), a(3), b(3), c(3)
    real(dp), intent(out) :: q(3), bary(3)
    integer, intent(out) :: region
    real(dp) :: ab(3), ac(3), bc(3), ap(3), bp(3), cp(3), n(3)
    real(dp) :: d1, d2, d3, d4, d5, d6, va, vb, vc, t, den, lmax

    ab = b - a
    ac = c - a
    bc = c - b
    ! |ab x ac|^2 = (l_max h_min)^2: thin or zero-area triangles go to the segment routine
    ! (the "not >" form also catches coincident vertices, where both sides are 0).
    n = [ab(2)*ac(3) - ab(3)*ac(2), ab(3)*ac(1) - ab(1)*ac(3), ab(1)*ac(2) - ab(2)*ac(1)]
    lmax = max(dot3(ab, ab), dot3(ac, ac), dot3(bc, bc))
    if (.not. (dot3(n, n) > thin_ratio2*lmax*lmax)) then
      call closest_point_segments(p, a, b, c, q, bary, region)
      return
    end if

    ap = p - a
    d1 = dot3(ab, ap)
    d2 = dot3(ac, ap)
    if (d1 <= 0.0_dp .and. d2 <= 0.0_dp) then
      call set_vertex(region_vertex_a, 1, a, q, bary, region)
      return
    end if

    bp = p - b
    d3 = dot3(ab, bp)
    d4 = dot3(ac, bp)
    if (d3 >= 0.0_dp .and. d4 <= d3) then
      call set_vertex(region_vertex_b, 2, b, q, bary, region)
      return
    end if

    vc = d1*d4 - d3*d2
    if (vc <= 0.0_dp .and. d1 >= 0.0_dp .and. d3 <= 0.0_dp) then
      ! d1 - d3 = |ab|^2 > 0 in exact arithmetic; the guard keeps a rounded 0 from giving 0/0.
      t = min(d1/max(d1 - d3, tiny(1.0_dp)), 1.0_dp)
      bary = [1.0_dp - t, t, 0.0_dp]
      q = a + t*ab
      region = region_edge_ab
      return
    end if

    cp = p - c
    d5 = dot3(ab, cp)
    d6 = dot3(ac, cp)
    if (d6 >= 0.0_dp .and. d5 <= d6) then
      call set_vertex(region_vertex_c, 3, c, q, bary, region)
      return
    end if

    vb = d5*d2 - d1*d6
    if (vb <= 0.0_dp .and. d2 >= 0.0_dp .and. d6 <= 0.0_dp) then
      t = min(d2/max(d2 - d6, tiny(1.0_dp)), 1.0_dp)   ! fraction from a towards c
      bary = [1.0_dp - t, 0.0_dp, t]
      q = a + t*ac
      region = region_edge_ca
      return
    end if

    va = d3*d6 - d5*d4
    if (va <= 0.0_dp .and. d4 - d3 >= 0.0_dp .and. d5 - d6 >= 0.0_dp) then
      t = min((d4 - d3)/max((d4 - d3) + (d5 - d6), tiny(1.0_dp)), 1.0_dp)   ! from b towards c
      bary = [0.0_dp, 1.0_dp - t, t]
      q = b + t*bc
      region = region_edge_bc
      return
    end if

    ! Face: va, vb, vc > 0 in exact arithmetic. If rounding broke that (nearly flat triangle),
    ! the boundary answer is as good and cannot divide by zero.
    if (.not. (va > 0.0_dp .and. vb > 0.0_dp .and. vc > 0.0_dp)) then
      call closest_point_segments(p, a, b, c, q, bary, region)
      return
    end if
    den = 1.0_dp/(va + vb + vc)
    bary = [va*den, vb*den, vc*den]
    q = a + bary(2)*ab + bary(3)*ac
    region = region_face

  end subroutine closest_point_triangle

  !> The closest point is vertex k (= v) of the triangle.
  pure subroutine set_vertex(reg, k, v, q, bary, region)
    integer, intent(in) :: reg, k
    real(dp), intent(in) :: v(3)
    real(dp), intent(out) :: q(3), bary(3)
    integer, intent(out) :: region
    bary = 0.0_dp
    bary(k) = 1.0_dp
    q = v
    region = reg
  end subroutine set_vertex

  !> Nearest point of the three clamped segments a-b, b-c, c-a (ties: the first); used for
  !> zero-area triangles, including coincident vertices (a zero-length segment is its start).
  pure subroutine closest_point_segments(p, a, b, c, q, bary, region)
    real(dp), intent(in) :: p(3), a(3), b(3), c(3)
    real(dp), intent(out) :: q(3), bary(3)
    integer, intent(out) :: region
    real(dp) :: qs(3), t, d2, best
    integer :: reg

    call segment(p, a, b, region_edge_ab, region_vertex_a, region_vertex_b, qs, t, reg)
    best = dot3(p - qs, p - qs)
    q = qs
    bary = [1.0_dp - t, t, 0.0_dp]
    region = reg

    call segment(p, b, c, region_edge_bc, region_vertex_b, region_vertex_c, qs, t, reg)
    d2 = dot3(p - qs, p - qs)
    if (d2 < best) then
      best = d2
      q = qs
      bary = [0.0_dp, 1.0_dp - t, t]
      region = reg
    end if

    call segment(p, c, a, region_edge_ca, region_vertex_c, region_vertex_a, qs, t, reg)
    d2 = dot3(p - qs, p - qs)
    if (d2 < best) then
      q = qs
      bary = [t, 0.0_dp, 1.0_dp - t]
      region = reg
    end if
  end subroutine closest_point_segments

  !> Closest point qs = u + t (v - u), t in [0, 1], of segment u-v; reg_u/reg_v when clamped.
  pure subroutine segment(p, u, v, reg_edge, reg_u, reg_v, qs, t, reg)
    real(dp), intent(in) :: p(3), u(3), v(3)
    integer, intent(in) :: reg_edge, reg_u, reg_v
    real(dp), intent(out) :: qs(3), t
    integer, intent(out) :: reg
    real(dp) :: uv(3), l2

    uv = v - u
    l2 = dot3(uv, uv)
    t = 0.0_dp
    if (l2 > 0.0_dp) t = dot3(p - u, uv)/l2
    if (t <= 0.0_dp) then
      t = 0.0_dp
      qs = u
      reg = reg_u
    else if (t >= 1.0_dp) then
      t = 1.0_dp
      qs = v
      reg = reg_v
    else
      qs = u + t*uv
      reg = reg_edge
    end if
  end subroutine segment

  pure real(dp) function dot3(u, v)
    real(dp), intent(in) :: u(3), v(3)
    dot3 = u(1)*v(1) + u(2)*v(2) + u(3)*v(3)
  end function dot3
end module casca_closest_point
