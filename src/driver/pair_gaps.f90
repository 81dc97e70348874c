!> What `casca check` says about each contact pair at t = 0: the smallest gap between the
!> surfaces in contact (faces: mid-surfaces less half of each reference thickness along the
!> fibre, as a constraint measures it: (h/2)|G.u|, rounded at a shell's free edge within 60
!> degrees of edge-on to (h/2) 3/16 edge-on (projection.f90's face), but h/2 all round for a
!> target's rim met by a one-pass pair's node; 'mid': the mid-surfaces) and
!> the time to contact at the bodies' initial velocities.
!>
!> The contact's own probe only sees nodes within the search radius, so the distance here is
!> computed from scratch, for bodies at any distance: every impactor node against every
!> sub-triangle of the target (the chords of its cubic elements, 9 per element), a triangle's
!> bounding box skipping it when it cannot beat the best so far. The answer is exact where
!> the closest point is a target node and overestimates the gap to a convex target's cubic
!> surface by at most the chord's sagitta, kappa e^2 / 8 (e: sub-triangle edge, kappa: the
!> target's curvature). An obstacle's distance is exact (obstacle_point).
!>
!> The time to contact is the earliest at which an impactor node, each moving straight on at
!> its initial velocity and the target's sub-triangles at their nodes' mean velocity, reaches
!> the target's face: the sub-triangle's plane offset by both faces (ray_time); a node whose
!> nearest target point is on a rim met edge-on (one pass) no later than its gap over its
!> closing speed (the relative velocity along the line to that point), as its path need not
!> meet a face there. No deformation, no gravity. Not the
!> closest node's gap over its speed alone: a ring inside a ring is nearest on the side it
!> moves away from (it said 'never'), and off the axis met the concave wall 19% late. An
!> obstacle's by each node's straight path to its face (obstacle_ray_time; a plane's is the
!> gap over the closing speed, a curved wall's is not). 'never' when no
!> node meets it; a body's own surface (self-contact) is never closed by its rigid motion.
!> The speed printed is the closest node's.
module casca_pair_gaps
  use casca_kinds, only: dp
  use casca_model, only: model_t, dof
  use casca_obstacle, only: obstacle_point, obstacle_ray_time
  use casca_closest_point, only: closest_point_triangle, region_edge_ab, region_vertex_a
  use casca_contact, only: contact_t, tested_both_ways
  use casca_contact_projection, only: face, positions, on_rim
  use casca_surface_search, only: surface_t
  use casca_vectors, only: cross
  implicit none
  private
  public :: pair_gap_t, pair_gaps, pair_gaps_at, pair_gap_lines

  !> One pair's figures at t = 0
  type :: pair_gap_t
    real(dp) :: gap = huge(1._dp)   !< smallest gap between the surfaces in contact [m]
    real(dp) :: speed = 0           !< closing speed at that closest approach [m/s]
    real(dp) :: time = -1           !< time to contact, the earliest node's [s]; < 0: never
    integer :: node = 0             !< the impactor node of the closest approach
    !> the earliest time is a node's meeting the target's free edge coming edge-first (one
    !> pass: edge_first)
    logical :: rim = .false.
  end type pair_gap_t

contains

  !> Gaps and times of every pair of c (made by contact_init) at positions x(3, nnode),
  !> fibres g(3, nnode) and velocities v(3, nnode).
  !> horizon: only times up to it are sought (a path that cannot reach the target within it
  !> is not followed), else any.
  function pair_gaps(c, model, x, g, v, horizon) result(pg)
    type(contact_t), intent(in) :: c
    type(model_t), intent(in) :: model
    real(dp), intent(in) :: x(:, :), g(:, :), v(:, :)
    real(dp), intent(in), optional :: horizon
    type(pair_gap_t) :: pg(c%npairs)
    integer :: ip, bi, bt, n, it, k, best_tri, region, best_region
    real(dp) :: nrm(3), d, q(3), bary(3), dist, best, best_bary(3), best_q(3), u(3), vt(3), gap, ft, vmax, &
                speed, tn, tl, tmax, reach
    logical :: rounded
    real(dp), allocatable :: lo(:, :), hi(:, :), vm(:, :), gm(:, :)
    logical :: rounded_rim   !< the pair meets its target's rim rounded (one pass)
    tmax = huge(1._dp)
    if (present(horizon)) tmax = horizon
    do ip = 1, c%npairs
      bi = c%pair(1, ip); bt = c%pair(2, ip)
      vmax = max_speed(c, model, v, bi, bt)
      associate (r => pg(ip), bd => model%body(bi))
        if (bt <= 0) then   ! an obstacle, where it is at t = 0
          associate (ob => c%obstacle(-bt))
            do n = bd%node_first, bd%node_last
              ! (a node held in place is never constrained: active_set.f90)
              if (all(model%fixed(dof(n, 1):dof(n, 3)))) cycle
              call obstacle_point(ob, 0._dp, x(:, n), nrm, d)
              gap = d - face_along(c, model, bi, g(:, n), nrm)
              speed = -dot_product(v(:, n) - ob%velocity, nrm)
              tn = closing_time(gap, speed, vmax)
              if (ob%shape /= 'plane' .and. gap > 0) then   ! (a curved wall: along the path)
                tn = -1
                u = v(:, n) - ob%velocity
                if (norm2(u) > 1e-12_dp*vmax) tn = obstacle_ray_time(ob, x(:, n), u, d - gap)
                do k = 1, 20   ! (the face's offset along the normal where it meets the wall)
                  if (tn <= 0) exit
                  tl = tn
                  call obstacle_point(ob, 0._dp, x(:, n) + tn*u, nrm, d)
                  tn = obstacle_ray_time(ob, x(:, n), u, face_along(c, model, bi, g(:, n), nrm))
                  if (abs(tn - tl) <= 1e-13_dp*tl) exit
                end do
              end if
              call note(r, n, gap, speed, tn, .false.)
            end do
          end associate
        else
          rounded_rim = bi /= bt .and. .not. tested_both_ways(c, bi, bt)
          associate (s => c%geo%surf(bt))
            allocate (lo(3, s%ntri), hi(3, s%ntri), vm(3, s%ntri), gm(3, s%ntri))
            do it = 1, s%ntri
              lo(:, it) = minval(x(:, s%tri(:, it)), dim=2)
              hi(:, it) = maxval(x(:, s%tri(:, it)), dim=2)
              vm(:, it) = sum(v(:, s%tri(:, it)), dim=2)/3   ! (the paths are taken relative to it)
              gm(:, it) = sum(g(:, s%tri(:, it)), dim=2)/3
            end do
            do n = bd%node_first, bd%node_last
              best = huge(1._dp); best_tri = 0
              do it = 1, s%ntri
                ! the box's distance is a lower bound of the triangle's
                if (norm2(max(lo(:, it) - x(:, n), 0._dp, x(:, n) - hi(:, it))) >= best) cycle
                ! self-contact: not the surface around the node (as the contact leaves it out)
                if (bi == bt) then
                  if (any([(norm2(model%x0(:, s%tri(k, it)) - model%x0(:, n)) < c%geo%skip(bt), &
                            k=1, 3)])) cycle
                end if
                call closest_point_triangle(x(:, n), x(:, s%tri(1, it)), x(:, s%tri(2, it)), &
                                            x(:, s%tri(3, it)), q, bary, region)
                dist = norm2(x(:, n) - q)
                if (dist < best) then
                  best = dist; best_tri = it; best_bary = bary; best_q = q; best_region = region
                end if
              end do
              if (best_tri == 0) cycle
              u = x(:, n) - best_q
              if (norm2(u) > 0) u = u/norm2(u)
              rounded = c%opt%faces .and. rounded_rim .and. on_rim(s, best_tri, best_region)
              if (rounded) then
                ft = 0.5_dp*model%body(bt)%thickness
              else
                ft = face_along(c, model, bt, matmul(g(:, s%tri(:, best_tri)), best_bary), u)
              end if
              gap = best - face_along(c, model, bi, g(:, n), u) - ft
              vt = matmul(v(:, s%tri(:, best_tri)), best_bary)
              speed = -dot_product(v(:, n) - vt, u)
              tn = -1
              reach = huge(1._dp)   ! (2 vmax tmax would overflow without a horizon)
              if (present(horizon)) reach = 2*vmax*tmax + model%body(bi)%thickness + model%body(bt)%thickness
              if (bi /= bt .and. best <= reach) tn = ray_time(c, model, s, x, g, v(:, n), vm, gm, &
                                                             bi, bt, n, lo, hi, vmax, tmax)
              if (rounded) then   ! (edge-on: the path need not meet a face)
                tl = closing_time(gap, speed, vmax)
                if (tl >= 0 .and. (tn < 0 .or. tl < tn)) tn = tl
              end if
              call note(r, n, gap, speed, tn, rounded .and. edge_first(s, x, best_tri, best_region, vt - v(:, n)))
            end do
            deallocate (lo, hi, vm, gm)
          end associate
        end if
        if (bi == bt) r%time = -1
        r%speed = r%speed + 0._dp   ! (no -0 printed)
      end associate
    end do
  end function pair_gaps

  !> The target's rim at the nearest point (region of sub-triangle it of s) advances on the
  !> node, relative velocity w, edge-first: w within 60 degrees of the rim's outward normal
  !> in the sub-triangle's plane (at a vertex, of its rim edges' summed). Not so for rings
  !> closing face to face, their rim nodes level, nor sliding along each other's rims, which
  !> are nearest at the rim too.
  pure logical function edge_first(s, x, it, region, w)
    type(surface_t), intent(in) :: s
    real(dp), intent(in) :: x(:, :), w(3)
    integer, intent(in) :: it, region
    real(dp) :: nrm(3), m(3), o(3), v(3, 3)
    integer :: e, k
    v = x(:, s%tri(:, it))
    nrm = cross(v(:, 2) - v(:, 1), v(:, 3) - v(:, 1))
    m = 0
    do e = 1, 3   ! (edges ab, bc, ca: from vertex e to the next)
      k = mod(e, 3) + 1
      if (.not. s%rim(e, it)) cycle
      if (.not. (region == region_edge_ab + e - 1 .or. region == region_vertex_a + e - 1 .or. &
                 region == region_vertex_a + k - 1)) cycle
      o = cross(v(:, k) - v(:, e), nrm)
      if (dot_product(o, v(:, mod(k, 3) + 1) - v(:, e)) > 0) o = -o   ! (away from the third)
      m = m + o/norm2(o)
    end do
    edge_first = dot_product(w, m) > 0.5_dp*norm2(w)*norm2(m) .and. norm2(m) > 0
  end function edge_first

  !> node n's gap, closing speed and time to contact tn (< 0: none; rim: at the target's rim
  !> edge-on): the pair's smallest gap and its earliest time
  pure subroutine note(r, n, gap, speed, tn, rim)
    type(pair_gap_t), intent(inout) :: r
    integer, intent(in) :: n
    real(dp), intent(in) :: gap, speed, tn
    logical, intent(in) :: rim
    if (gap < r%gap) then
      r%gap = gap; r%node = n; r%speed = speed
    end if
    if (tn >= 0 .and. (r%time < 0 .or. tn < r%time)) then
      r%time = tn; r%rim = rim
    end if
  end subroutine note

  !> gap over closing speed; -1 unless it closes faster than rounding of the bodies' speeds
  !> vmax (a rigid body's own surface gives 0 to rounding)
  pure real(dp) function closing_time(gap, speed, vmax) result(t)
    real(dp), intent(in) :: gap, speed, vmax
    t = -1
    if (speed > 1e-12_dp*vmax) t = max(gap, 0._dp)/speed
  end function closing_time

  !> The earliest time at which node n of body bi (fibres g, velocity vn), moving straight on
  !> relative to each sub-triangle of surface s (at its nodes' mean velocity vm; mean fibre
  !> gm), comes within both faces' offset of that sub-triangle's plane with its foot inside
  !> it, or, aimed at its edge, of the triangle itself; -1 if never or after tmax. lo, hi: the
  !> sub-triangles' boxes, which a path that cannot reach them within the best time skips.
  real(dp) function ray_time(c, model, s, x, g, vn, vm, gm, bi, bt, n, lo, hi, vmax, tmax) result(t)
    type(contact_t), intent(in) :: c
    type(model_t), intent(in) :: model
    type(surface_t), intent(in) :: s
    real(dp), intent(in) :: x(:, :), g(:, :), vn(3), vm(:, :), gm(:, :), lo(:, :), hi(:, :), vmax, tmax
    integer, intent(in) :: bi, bt, n
    real(dp) :: w(3), a(3), e1(3), e2(3), nt(3), sd, side, off, th, tc, p(3), q(3), bary(3), grow, gn(3)
    integer :: it, region
    logical :: found
    gn = g(:, n)
    found = .false.
    t = tmax
    grow = 0
    if (c%opt%faces) grow = 0.5_dp*(model%body(bi)%thickness + model%body(bt)%thickness)
    do it = 1, s%ntri
      w = vn - vm(:, it)
      if (.not. path_meets_box(x(:, n), w, t, lo(:, it) - grow, hi(:, it) + grow)) cycle
      a = x(:, s%tri(1, it)); e1 = x(:, s%tri(2, it)) - a; e2 = x(:, s%tri(3, it)) - a
      nt = cross(e1, e2)
      if (norm2(nt) == 0) cycle
      nt = nt/norm2(nt)
      sd = dot_product(x(:, n) - a, nt)
      side = merge(1._dp, -1._dp, sd >= 0)
      off = face_along(c, model, bi, gn, -side*nt) + face_along(c, model, bt, gm(:, it), side*nt)
      th = 0
      if (abs(sd) > off) th = closing_time(abs(sd) - off, -side*dot_product(w, nt), vmax)
      if (th < 0 .or. th > t) cycle   ! (not closing on the plane, or later)
      p = x(:, n) + th*w
      p = p - dot_product(p - a, nt)*nt   ! (its foot on the plane)
      call closest_point_triangle(p, a, a + e1, a + e2, q, bary, region)
      if (norm2(q - p) > 1e-9_dp*max(norm2(e1), norm2(e2))) then
        ! (the foot is off the triangle. A path aimed at a convex edge or corner of the chords
        ! hits each offset plane with its foot off that plane's triangle, on the far side of
        ! the edge: a sphere's node aimed at the chord between two of another sphere's nodes
        ! was missed by both, and check said 4.9e-4 s for a touch the run made at 3.5e-4 s.
        ! The path then meets the triangle's offset later than its plane, if at all: where its
        ! distance to the triangle is off, before it crosses the plane. w's part along the
        ! plane bounds how fast the foot can come back.)
        tc = abs(sd)/(-side*dot_product(w, nt))
        if (norm2(q - p) - norm2(w - dot_product(w, nt)*nt)*(tc - th) > max(off, grow)) cycle
        th = offset_time(th, min(tc, t))
        if (th < 0) cycle
      end if
      t = th; found = .true.
    end do
    if (.not. found) t = -1
  contains

  !> The first time in [t0, t1] at which node n's path comes within both faces' offset of
  !> sub-triangle it (a, a + e1, a + e2), each along the line from the triangle's nearest
  !> point to the path, with the target's fibre there (at a crease's edge the plane's normal
  !> gave the fibres' offsets a third less: a ball's node aimed at a prism's 60-degree crease
  !> was said 5.62e-4 s for a touch at 4.79e-4 s); -1 if it does not. The distance to a
  !> triangle is convex along a line, and its offset changes slowly: golden sections close
  !> in on the least excess until one is within, and bisection finds the first time between.
  real(dp) function offset_time(t0, t1) result(t)
    real(dp), intent(in) :: t0, t1
    real(dp), parameter :: golden = 0.6180339887498949_dp
    real(dp) :: lo, hi, m1, m2, f1, f2, tp
    integer :: k
    t = -1
    if (t1 < t0) return
    tp = -1
    if (excess(t1) <= 0) tp = t1
    lo = t0; hi = t1
    do k = 1, 100
      if (tp >= 0 .or. hi - lo <= 1e-12_dp*t1) exit
      m1 = hi - golden*(hi - lo); m2 = lo + golden*(hi - lo)
      f1 = excess(m1); f2 = excess(m2)
      if (f1 <= 0) then
        tp = m1
      else if (f2 <= 0) then
        tp = m2
      else if (f1 < f2) then
        hi = m2
      else
        lo = m1
      end if
    end do
    if (tp < 0) return
    lo = t0; hi = tp
    do k = 1, 60
      m1 = 0.5_dp*(lo + hi)
      if (excess(m1) <= 0) then
        hi = m1
      else
        lo = m1
      end if
    end do
    t = hi
  end function offset_time

  real(dp) function excess(tau)
    real(dp), intent(in) :: tau
    real(dp) :: y(3), q(3), bary(3), u(3), d
    integer :: region
    y = x(:, n) + tau*w
    call closest_point_triangle(y, a, a + e1, a + e2, q, bary, region)
    d = norm2(y - q)
    u = nt
    if (d > 0) u = (y - q)/d
    excess = d - face_along(c, model, bi, gn, -u) - face_along(c, model, bt, matmul(g(:, s%tri(:, it)), bary), u)
  end function excess
  end function ray_time

  !> the path x + w t, 0 <= t <= tmax, meets the box [lo, hi] (slabs)
  pure logical function path_meets_box(x, w, tmax, lo, hi) result(meets)
    real(dp), intent(in) :: x(3), w(3), tmax, lo(3), hi(3)
    real(dp) :: t0, t1, ta, tb
    integer :: k
    t0 = 0; t1 = tmax
    meets = .false.
    do k = 1, 3
      if (w(k) == 0) then
        if (x(k) < lo(k) .or. x(k) > hi(k)) return
        cycle
      end if
      ta = (lo(k) - x(k))/w(k); tb = (hi(k) - x(k))/w(k)
      t0 = max(t0, min(ta, tb)); t1 = min(t1, max(ta, tb))
      if (t0 > t1) return
    end do
    meets = .true.
  end function path_meets_box
  !> pair_gaps at the parameters q and their rates qd (ndof): positions, fibres, velocities
  function pair_gaps_at(c, model, q, qd, horizon) result(pg)
    type(contact_t), intent(in) :: c
    type(model_t), intent(in) :: model
    real(dp), intent(in) :: q(:), qd(:)
    real(dp), intent(in), optional :: horizon
    type(pair_gap_t) :: pg(c%npairs)
    pg = pair_gaps(c, model, positions(model, q), positions(model, q, fibres=.true.), positions(model, qd), &
                   horizon)
  end function pair_gaps_at

  !> body b's face along u, as a new constraint chooses it (projection.f90); none between
  !> mid-surfaces. (Module procedures, not internal ones: gfortran gave the binary an
  !> executable stack for them.)
  real(dp) function face_along(c, model, b, gf, u)
    type(contact_t), intent(in) :: c
    type(model_t), intent(in) :: model
    integer, intent(in) :: b
    real(dp), intent(in) :: gf(3), u(3)
    integer :: s
    real(dp) :: w
    face_along = 0
    if (.not. c%opt%faces) return
    s = 0
    call face(model%body(b)%thickness, gf, u, s, face_along, w)
  end function face_along

  !> the fastest node of bodies b1 and b2 (or obstacle -b2)
  real(dp) function max_speed(c, model, v, b1, b2)
    type(contact_t), intent(in) :: c
    type(model_t), intent(in) :: model
    real(dp), intent(in) :: v(:, :)
    integer, intent(in) :: b1, b2
    integer :: m
    max_speed = tiny(1._dp)
    do m = model%body(b1)%node_first, model%body(b1)%node_last
      max_speed = max(max_speed, norm2(v(:, m)))
    end do
    if (b2 <= 0) then
      max_speed = max(max_speed, norm2(c%obstacle(-b2)%velocity))
      return
    end if
    do m = model%body(b2)%node_first, model%body(b2)%node_last
      max_speed = max(max_speed, norm2(v(:, m)))
    end do
  end function max_speed

  !> One line per pair: names(t) is target t's name (bodies t > 0, obstacles t = -k), then a
  !> line saying how the gap was measured.
  function pair_gap_lines(c, pg, body_names, obstacle_names) result(lines)
    type(contact_t), intent(in) :: c
    type(pair_gap_t), intent(in) :: pg(:)
    character(len=*), intent(in) :: body_names(:), obstacle_names(:)
    character(len=320), allocatable :: lines(:)
    character(len=:), allocatable :: tname, kind
    character(len=40) :: when
    character(len=10) :: skip
    integer :: ip, bi, bt
    allocate (lines(size(pg) + 1))
    do ip = 1, size(pg)
      bi = c%pair(1, ip); bt = c%pair(2, ip)
      if (bt > 0) then
        tname = trim(body_names(bt)); kind = ''
        if (bt == bi) then   ! (what a fold closer than this cannot touch: say it)
          write (skip, '(es10.3)') c%geo%skip(bt)
          kind = ' (self-contact; the surface within '//trim(adjustl(skip))// &
                 ' m of a node at the start is not tested against it)'
        end if
      else
        tname = trim(obstacle_names(-bt)); kind = ' (obstacle)'
      end if
      if (pg(ip)%node == 0) then
        write (lines(ip), '(6a)') 'pair ''', trim(body_names(bi)), ''' -> ''', tname, ''''//kind, &
          ': no node to measure (every node held, or nothing beyond its own neighbourhood)'
        cycle
      end if
      when = 'never'
      if (pg(ip)%time >= 0) write (when, '(es14.7,a)') pg(ip)%time, ' s'
      write (lines(ip), '(6a,es14.7,a,es14.7,2a)') 'pair ''', trim(body_names(bi)), ''' -> ''', &
        tname, ''''//kind, ': gap ', pg(ip)%gap, ' m, closing speed ', pg(ip)%speed, &
        ' m/s, time to contact ', trim(adjustl(when))
    end do
    if (c%opt%faces) then
      lines(size(pg) + 1) = '(gaps between the shell faces, half of each thickness from the '// &
        'mid-surfaces; to the target''s sub-triangles: exact at its nodes, chords between them; '// &
        'times at the initial velocities, without deformation or gravity)'
    else
      lines(size(pg) + 1) = '(gaps between the mid-surfaces; to the target''s sub-triangles: '// &
        'exact at its nodes, chords between them; times at the initial velocities, without '// &
        'deformation or gravity)'
    end if
  end function pair_gap_lines
end module casca_pair_gaps
