!> One constraint's geometry: the target point of a node (nearest sub-triangle of the target,
!> or the closest point of an obstacle), and at that point the shape functions, the normal
!> and the gap between the faces.
!>
!> The faces lie at half the thickness from the mid-surface along the current fibre G: a
!> face is (h0/2) G.n away from the mid-surface along n (see face() for the thickness). The
!> constraint's row holds the offset's derivative on G, so the contact force acts at the face
!> and does work through the fibre's turn. (Held in the linearisation instead, the offset's
!> change from step to step did work no force paid for: a ring bouncing on a floor with the
!> trapezoidal rule ended with 5600 times its energy.)
!>
!> With Coulomb friction a sticking constraint has two more rows, the relative tangential
!> displacement of the node over the step (along t1, t2 across n), and a sliding one carries
!> a force mu_d |lambda| against its slip direction s, the slip's at each iterate.

module casca_contact_projection
  use casca_kinds, only: dp
  use casca_model, only: model_t, dof
  use casca_shape_tri10, only: tri10_shape, tri10_normal
  use casca_vectors, only: cross
  use casca_surface_search, only: surface_t, grid_build, nearest_subtriangle, subtri_parent_xi
  use casca_obstacle, only: obstacle_point
  use casca_closest_point, only: region_face, region_edge_ab, region_edge_bc, region_edge_ca, &
                                 region_vertex_a, region_vertex_b, region_vertex_c
  use casca_contact, only: contact_t, constraint_t, search_radius, tested_both_ways, max_lever, &
                           slip_followed, around_rim
  implicit none
  private
  public :: positions, body_box, project, constraint_geometry, constraint_entries, constraint_row, face, &
            force_point, row_factors, normal_cache_t, normal_cache, on_rim

  !> The targets' element normals at their nodes for one set of positions, each made when a
  !> nodal normal first needs it: neighbouring constraints share nodes, and each normal sums
  !> those of the elements around its 10 nodes (three quarters of the contact time of two
  !> sheets draped over a ball went into making them again)
  type :: normal_cache_t
    real(dp), allocatable :: n(:, :, :)   !< (3, 10, nelem) unit normal of element e at its node k
    logical, allocatable :: made(:, :)    !< (10, nelem)
  end type normal_cache_t

  integer, parameter, public :: max_row = 66 + 3*max_lever   !< 11 nodes x (Y, G), the lever's nodes
  integer, parameter, public :: across = 4     !< the row kind across the slip (row_factors)
  !> how far outside its element (least area coordinate) a force point is still kept: the
  !> polynomial face holds just beyond the edge, its weights still summing to one
  real(dp), parameter :: beyond_element = -0.25_dp

contains

  !> The mid-surface positions (3, nnode) of q, or its fibres
  pure function positions(model, q, fibres) result(x)
    type(model_t), intent(in) :: model
    real(dp), intent(in) :: q(:)
    logical, intent(in), optional :: fibres   !< .true.: the fibres G instead
    real(dp) :: x(3, model%nnode)
    integer :: n, m
    m = 0
    if (present(fibres)) m = merge(3, 0, fibres)
    do n = 1, model%nnode
      x(:, n) = q(dof(n, m + 1):dof(n, m + 3))
    end do
  end function positions

  !> Bounding box (3, 2: min and max corner) of body b at positions x
  pure function body_box(model, x, b) result(bx)
    type(model_t), intent(in) :: model
    real(dp), intent(in) :: x(:, :)
    integer, intent(in) :: b
    real(dp) :: bx(3, 2)
    associate (bd => model%body(b))
      bx(:, 1) = minval(x(:, bd%node_first:bd%node_last), dim=2)
      bx(:, 2) = maxval(x(:, bd%node_first:bd%node_last), dim=2)
    end associate
  end function body_box

  !> The target point of node on the body target of pair p (nearest sub-triangle within the
  !> pair's search radius): con%elem, con%xi, con%sd (signed distance to the sub-triangle,
  !> positive on its normal's side). ok = .false. when nothing is within reach.
  subroutine project(c, model, x, node, p, con, ok)
    type(contact_t), intent(inout) :: c
    type(model_t), intent(in) :: model
    real(dp), intent(in) :: x(:, :)
    integer, intent(in) :: node, p
    type(constraint_t), intent(out) :: con
    logical, intent(out) :: ok
    integer :: bi, bt, itri, region
    real(dp) :: xq(3), bary(3), dist, nt(3), near(3, 2), r
    logical :: rim
    bi = c%pair(1, p); bt = c%pair(2, p)
    r = search_radius(c, model, bi, bt)
    associate (g => c%geo)
      if (.not. g%grid_ok(p)) then   ! the target's sub-triangles within reach of the impactor
        near = body_box(model, x, bi)
        near(:, 1) = near(:, 1) - r; near(:, 2) = near(:, 2) + r
        call grid_build(g%surf(bt), x, g%grid(p), near)
        g%grid_ok(p) = .true.
      end if
      if (bi == bt) then   ! self-contact: not the surface around the node
        call nearest_subtriangle(g%surf(bt), g%grid(p), x, x(:, node), r, ok, itri, xq, bary, &
                                 dist, region, model%x0, model%x0(:, node), g%skip(bt))
      else
        call nearest_subtriangle(g%surf(bt), g%grid(p), x, x(:, node), r, ok, itri, xq, bary, &
                                 dist, region)
      end if
      if (.not. ok) return
      associate (t => g%surf(bt)%tri(:, itri))
        nt = cross(x(:, t(2)) - x(:, t(1)), x(:, t(3)) - x(:, t(1)))
      end associate
      con%sd = sign(dist, dot_product(x(:, node) - xq, nt))
      ! nearest on an open surface's rim (an edge or a vertex of it) the node meets the rim's
      ! edge, rounded by the faces' offsets (rim_normal). Taken along the face's normal there,
      ! a hoop passing a plate's edge was thrown back with 60 times its energy; left free, a
      ! ball dropped on a ring's rim sank in between its faces and was pushed out sideways
      ! (17 times E0 in a step). (Between mid-surfaces the edge has no thickness to meet.)
      ! When the pair is also tested the other way round, the rim's own nodes meet this
      ! body's face there, and a node held on the rim too fought them (a blade dropped
      ! edge-first onto a plate, 60 degrees from it, made 1.1 times the energy in a step):
      ! left out. Elsewhere, off to the side of the sub-triangle's plane, there is nothing to
      ! press on (across an edge inside a surface the node lies within the neighbours'
      ! normals, well inside this cone).
      if (region /= region_face) then
        rim = bi /= bt .and. on_rim(g%surf(bt), itri, region)
        if (rim .and. tested_both_ways(c, bi, bt)) then
          ok = .false.
          return
        else if (rim .and. c%opt%faces) then
          con%side = around_rim; con%sd = dist
        else if (abs(dot_product(x(:, node) - xq, nt)) < 0.5_dp*dist*norm2(nt)) then
          ok = .false.
          return
        end if
      end if
      con%node = node; con%pair = p; con%elem = g%surf(bt)%elem(itri)
      call subtri_parent_xi(g%surf(bt), itri, bary, con%xi)
    end associate
  end subroutine project

  !> The nearest point (region of sub-triangle itri) is on the surface's rim
  pure logical function on_rim(surf, itri, region)
    type(surface_t), intent(in) :: surf
    integer, intent(in) :: itri, region
    select case (region)
    case (region_edge_ab, region_edge_bc, region_edge_ca)
      on_rim = surf%rim(region - region_edge_ab + 1, itri)
    case (region_vertex_a, region_vertex_b, region_vertex_c)
      on_rim = surf%rim_vertex(region - region_vertex_a + 1, itri)
    case default
      on_rim = .false.
    end select
  end function on_rim

  !> An empty cache of the normals for a new set of positions
  subroutine normal_cache(model, cache)
    type(model_t), intent(in) :: model
    type(normal_cache_t), intent(inout) :: cache
    if (.not. allocated(cache%made)) allocate (cache%n(3, 10, model%nelem), cache%made(10, model%nelem))
    cache%made = .false.
  end subroutine normal_cache

  !> Shape functions, normal (towards the node's side), faces' offset and gap of con at its
  !> point; for an obstacle (con%elem = 0 on an obstacle pair) the point is found here.
  !> normals: the element normals made so far at these positions x. lever: between faces,
  !> the gap's derivative through the target normal's turn as well (normal_lever: for the
  !> rows of an active constraint; else con%nl = 0).
  subroutine constraint_geometry(c, model, x, q, con, normals, lever)
    type(contact_t), intent(in) :: c
    type(model_t), intent(in) :: model
    real(dp), intent(in) :: x(:, :), q(:)
    type(constraint_t), intent(inout) :: con
    type(normal_cache_t), intent(inout), optional :: normals
    logical, intent(in), optional :: lever
    real(dp) :: dphi(10, 2), xt(3), xe(3, 10), m(3), gm, gt(3), ft, te(3), tw(10), tl
    real(dp) :: lg(3, max_lever)
    integer :: j, nd, bi, bt, nlv, ln(max_lever)
    logical :: rim
    bi = c%pair(1, con%pair); bt = c%pair(2, con%pair)
    con%off = 0; con%wg = 0; con%wgg = 0; con%nl = 0
    if (bt <= 0) then
      con%elem = 0; con%side = 1; con%shp = 0
      call obstacle_point(c%obstacle(-bt), c%time, x(:, con%node), con%n, gm)
      if (c%opt%faces) call face(model%body(bi)%thickness, q(dof(con%node, 4):dof(con%node, 6)), &
                             -con%n, con%face(1), con%off, con%wg(1), c%rim(con%node), con%wgg)
      con%gap = gm - con%off - con%hold
      call hold_force_point(con)
      call friction_geometry()
      return
    end if
    call tri10_shape(con%xi(1), con%xi(2), con%shp, dphi)
    xe = x(:, model%conn(:, con%elem))   ! gathered once for the point and both tangents
    xt = matmul(xe, con%shp)
    rim = con%side == around_rim
    if (rim) then
      call rim_normal(xe, dphi, con%xi, x(:, con%node) - xt, con%n, te, tw, tl)
    else if (c%opt%nodal_normal) then
      con%n = 0
      do j = 1, 10
        call node_normal_sum(c, model, x, model%conn(j, con%elem), m, normals)
        con%n = con%n + (con%shp(j)/norm2(m))*m
      end do
    else
      con%n = unit_normal(xe, dphi)
    end if
    con%n = con%n/norm2(con%n)
    gm = dot_product(x(:, con%node) - xt, con%n)
    ! between mid-surfaces the target is one-sided (the thesis: its normal's side); between
    ! faces a shell is two-sided and the node stays on the side it came from
    if (con%side == 0) then
      con%side = 1
      if (c%opt%faces) con%side = int(sign(1._dp, gm))
    end if
    if (.not. rim) con%n = con%side*con%n
    if (c%opt%faces) then
      gt = 0
      do j = 1, 10
        nd = model%conn(j, con%elem)
        gt = gt + con%shp(j)*q(dof(nd, 4):dof(nd, 6))
      end do
      ! the impactor's face towards the target (along -n), the target's towards the node;
      ! around a rim n turns across the node's fibre, so the node's face is the one towards
      ! the edge at each iterate (held, a plate's node beside a cylinder's open end kept its
      ! far face as n turned: the offset changed sign, 2.9% of E0 in a step; faded as n lies
      ! in the node's plane, as at a rim node, the offset grew back by h/2 over 15 degrees
      ! of n's turn: 18% in a step)
      if (rim) con%face(1) = 0
      call face(model%body(bi)%thickness, q(dof(con%node, 4):dof(con%node, 6)), -con%n, con%face(1), &
                con%off, con%wg(1), c%rim(con%node), con%wgg)
      if (rim) then   ! (its edge rounded: h/2 all round, as beside it; no moment on its fibres)
        ft = 0.5_dp*model%body(bt)%thickness; con%wg(2) = 0
      else
        call face(model%body(bt)%thickness, gt, con%n, con%face(2), ft, con%wg(2))
      end if
      con%off = con%off + ft
      con%wg(2) = -con%wg(2)
      ! the gap's derivative through n: D . dn, D = Y - T + wg1 G + wg2 G_t, whose part across
      ! n (the face point P off the node's projection by up to (h/2) sin in the rim's
      ! rounding) turns the gap with the target's normal
      if (present(lever)) then
        if (lever .and. rim) then
          call rim_lever(model, con, x(:, con%node) - xt, con%wg(1)*q(dof(con%node, 4):dof(con%node, 6)) &
                         + con%wg(2)*gt, te, tw, tl)
        else if (lever) then
          call normal_lever(c, model, x, con, x(:, con%node) - xt + &
                            con%wg(1)*q(dof(con%node, 4):dof(con%node, 6)) + con%wg(2)*gt, &
                            nlv, ln, lg, normals)
          call set_lever(con, ln(1:nlv), lg(:, 1:nlv))
        end if
      end if
    end if
    con%gap = merge(gm, con%side*gm, rim) - con%off - con%hold
    call hold_force_point(con)
    call friction_geometry()
  contains
    !> tangents (the first kept from the last, turned across n) and the relative tangential
    !> displacement of the node over the step
    subroutine friction_geometry()
      real(dp) :: u(3), t1(3), e(3)
      integer :: jj, nd
      if (con%grip == 0) return
      t1 = con%t(:, 1) - dot_product(con%t(:, 1), con%n)*con%n
      if (norm2(t1) < 0.5_dp) then   ! (a new constraint: any direction across n)
        t1 = [con%n(2), -con%n(1), 0._dp]
        if (norm2(t1) < 0.5_dp) t1 = [0._dp, con%n(3), -con%n(2)]
        ! a node restrained along an axis in its tangent plane (a symmetry plane through the
        ! contact): that axis first, so that its stick row is the restraint's alone and left
        ! out (contact_rows), not half of two rows that the restraint makes dependent
        do jj = 1, 3
          if (.not. model%fixed(dof(con%node, jj))) cycle
          e = 0; e(jj) = 1
          e = e - dot_product(e, con%n)*con%n
          if (norm2(e) > 0.99_dp) then
            t1 = e; exit
          end if
        end do
      end if
      con%t(:, 1) = t1/norm2(t1)
      con%t(:, 2) = cross(con%n, con%t(:, 1))
      ! between faces the slip is the faces' (P = Y + wg(1) G, T = sum_j N_j (Y_j - wg(2) G_j)):
      ! a hoop rolls without slipping on its outer face, not on its mid-surface
      u = x(:, con%node) - c%x_start(:, con%node) + con%wg(1)*fibre_change(con%node)
      if (con%elem > 0) then
        do jj = 1, 10
          nd = model%conn(jj, con%elem)
          u = u - con%shp(jj)*(x(:, nd) - c%x_start(:, nd) - con%wg(2)*fibre_change(nd))
        end do
      else
        u = u - c%dt*c%obstacle(-bt)%velocity
      end if
      u = u - con%u0
      con%ut = u - dot_product(u, con%n)*con%n
      con%gt = [dot_product(u, con%t(:, 1)), dot_product(u, con%t(:, 2))]
      ! a sliding force is against the slip of this iterate, not of the step before: held
      ! through the step, s lagged a step, and where mu_d |lambda| / |ut| is as stiff as
      ! the node (a ball glancing down a slope) the lag overshot, growing 1.65 times a step
      if (slip_followed(c, con)) con%s = con%ut/norm2(con%ut)
    end subroutine friction_geometry

    !> the change of node k's fibre over the step
    function fibre_change(k) result(dg)
      integer, intent(in) :: k
      real(dp) :: dg(3)
      dg = q(dof(k, 4):dof(k, 6)) - c%g_start(:, k)
    end function fibre_change
  end subroutine constraint_geometry

  !> Distance f along u of face s of a shell, (h/2) s G.u (along the current fibre, at the
  !> reference thickness), and w = (h/2) s, its derivative along -u.dG (the sign the gap
  !> takes for the face towards u). s = 0 (a new constraint) chooses, then holds, the face
  !> towards u. Where the shell may touch with its edge (rim: a node on its shell's free
  !> edge; rim absent: the target's side) its edge is rounded: f = (h/2) rho(k), k = G.u,
  !> rho = |k| from |k| = 0.5 (60 degrees, G being of about unit length) and within it the
  !> even quartic 3 d/8 + 3 k^2 / (4 d) - k^4 / (8 d^3), d = 0.5, which meets |k| with its
  !> slope and curvature there: convex, so a pressed edge's fibre is held by the contact, no
  !> moment on it edge-on (a strip meeting a wall edge-on: the pressure spreads over the
  !> edge's thickness), an offset of (h/2) 3/16 there, and the face towards u whichever side
  !> the fibre turns to. (Until 2026-11-28 the offset faded to 0 by a smoothstep in |k| from
  !> 0.5 to 0.25: its curvature was negative near 0.5, as stiff as the fibre under a crushed
  !> tube's edge forces, and the tube crushed in self-contact stopped at 0.348 of 1 ms with
  !> Newton wandering on its edge fibres; rounded, it runs to the end.) f depends on G
  !> through k alone, so w is its whole derivative (a stretch of G left out of the row: a
  !> thick blade landing at 62 degrees on a rigid plane gained 2.5% of E0 through its contact,
  !> now 1e-11; against a body the row needs n's turn as well, normal_lever: a blade 8 x 8
  !> landing at 60 degrees on a plate gained 9.8% of E0 without it, none with it). (Until
  !> 2026-11-27 an edge was chosen past 60 degrees, with offset 0 against the face's h/4
  !> there: a blade landing at 60 degrees, its fibres shaking across that angle, had nodes
  !> found at the edge's gap and taken again at the face's, h/4 deep, and pushed out in one
  !> step: 16 times E0. A node inside a shell lost 19% of a rubber ball's E0 the same way,
  !> and has no edge.) (The element's face, (h/2)(s + a) G, moves with the thickness
  !> parameter a too; but a has no mass and follows the contact force within a step, and fed
  !> back through the offset it made the trapezoidal rule unstable: a ring on a floor had a
  !> grow from 3e-4 to 9e-2 in ten steps.)
  pure subroutine face(h, g, u, s, f, w, rim, w2)
    real(dp), intent(in) :: h, g(3), u(3)
    integer, intent(inout) :: s
    real(dp), intent(out) :: f, w
    logical, intent(in), optional :: rim
    real(dp), intent(out), optional :: w2   !< f's second derivative along u.dG
    real(dp), parameter :: d = 0.5_dp
    real(dp) :: k
    logical :: edge_ok
    edge_ok = .true.
    if (present(rim)) edge_ok = rim
    k = dot_product(g, u)
    if (s == 0 .or. s == 2) s = merge(1, -1, k >= 0)   ! (2: an edge, in older checkpoints)
    if (present(w2)) w2 = 0
    if (.not. edge_ok) then
      f = 0.5_dp*h*s*k
      w = 0.5_dp*h*s
      return
    end if
    s = merge(1, -1, k >= 0)   ! (the face towards u: rho is even)
    if (abs(k) >= d) then
      f = 0.5_dp*h*abs(k)
      w = 0.5_dp*h*s
    else
      f = 0.5_dp*h*(3*d/8 + 3*k*k/(4*d) - k**4/(8*d**3))
      w = 0.5_dp*h*(3*k/(2*d) - k**3/(2*d**3))
      if (present(w2)) w2 = 0.5_dp*h*(3/(2*d) - 3*k*k/(2*d**3))
    end if
  end subroutine face

  !> The nodes a constraint acts on and the weights of its row of C: n on the impactor node,
  !> -N_j n on the target element's nodes (none for an obstacle). m: how many. force: at
  !> the point where the force acts (shpf), else the gap's (shp).
  pure subroutine constraint_entries(con, model, nodes, w, m, force)
    type(constraint_t), intent(in) :: con
    type(model_t), intent(in) :: model
    integer, intent(out) :: nodes(11), m
    real(dp), intent(out) :: w(11)
    logical, intent(in), optional :: force
    nodes(1) = con%node; w(1) = 1
    m = 1
    if (con%elem == 0) return
    nodes(2:) = model%conn(:, con%elem); w(2:) = -con%shp
    if (present(force)) then
      if (force) w(2:) = -con%shpf
    end if
    m = 11
  end subroutine constraint_entries

  !> Row of C of one constraint as a scalar row over the nodes' vector parameters times a
  !> direction: C_row = sum_j w(j) e(node(j), par(j)) (x) dir, par 0 the mid-surface point Y,
  !> 1 the fibre G (the Y entries first). kind 0: the normal row along n; kind 1, 2: the stick
  !> rows along t1, t2; kind 3: along the slip direction s (the sliding force's, mu_d |lambda|
  !> on it); kind 4 (across): across s in the tangent plane, n x s. Each acts on the
  !> mid-surface points and, between faces, on the fibres that carry the offset: the faces
  !> touch, and stick or slide, where they are. force: the row as the
  !> force acts, at shpf, friction included (at the gap's point, half a step's slide away,
  !> the friction pair had a moment: a spinning ball rattling in a shell lost 2.9e-4 of L
  !> in one impact, 3.5e-6 at shpf, test_friction 'rattle'). (The correction's mass solves
  !> need the scalar row only: one column per row, not one per component.)
  pure subroutine row_factors(a, model, kind, force, node, par, w, nw, dir, point)
    type(constraint_t), intent(in) :: a
    type(model_t), intent(in) :: model
    integer, intent(in) :: kind
    logical, intent(in) :: force
    !> .true.: the force's row at its force point without the lever (the velocity
    !> correction's: its rows are scalar rows times one direction, and the pair on one line
    !> keeps the angular momentum)
    logical, intent(in), optional :: point
    integer, intent(out) :: node(2*11), par(2*11), nw
    real(dp), intent(out) :: w(2*11), dir(3)
    integer :: j, nn
    real(dp) :: wg(2)
    logical :: lever
    select case (kind)
    case (0); dir = merge(a%nf, a%n, force)
    case (1, 2); dir = a%t(:, kind)
    case (across)
      dir = cross(a%n, a%s)
      if (norm2(dir) > 0) dir = dir/norm2(dir)
    case default; dir = a%s
    end select
    ! a normal row with its lever is the gap's gradient itself, where the force is taken too
    ! (at the gap's point: moment-free there as the gradient of a gap that turns with the
    ! bodies, so the force point is not wanted)
    lever = kind == 0 .and. a%nl > 0
    if (present(point)) then
      if (point .and. lever .and. force) then
        lever = .false.; dir = a%n   ! (nf: the lever's normal, where the force is taken)
      end if
    end if
    call constraint_entries(a, model, node(1:11), w(1:11), nn, force .and. .not. lever)
    par(1:nn) = 0
    nw = nn
    wg = a%wg
    if (force .and. lever) wg = a%wgf
    ! (every kind: the stick and slip rows are the faces' too; the pattern follows wg and wgf
    ! only, so that the gap's and the force's rows and every kind list the same parameters)
    if (all(a%wg == 0) .and. all(a%wgf == 0)) return
    do j = 1, nn
      if (merge(a%wg(1), a%wg(2), j == 1) == 0 .and. merge(a%wgf(1), a%wgf(2), j == 1) == 0) cycle
      nw = nw + 1; node(nw) = node(j); par(nw) = 1
      w(nw) = merge(wg(1), -w(j)*wg(2), j == 1)   ! (-w(j) = N_j on the target)
    end do
  end subroutine row_factors

  !> Row of C of one constraint (row_factors) as parameters d(1:nd) and values v(1:nd): the
  !> mid-surface points' components first, then the fibres' node by node, so that rows of
  !> one constraint list the same parameters in the same order.
  pure subroutine constraint_row(a, model, d, v, nd, kind, force)
    type(constraint_t), intent(in) :: a
    type(model_t), intent(in) :: model
    integer, intent(out) :: d(max_row), nd
    real(dp), intent(out) :: v(max_row)
    integer, intent(in), optional :: kind
    logical, intent(in), optional :: force
    integer :: j, comp, node(22), par(22), nw, ny, kd, l, i
    real(dp) :: w(22), dir(3), lg(3)
    logical :: at_force
    kd = 0
    if (present(kind)) kd = kind
    at_force = .false.
    if (present(force)) at_force = force
    call row_factors(a, model, kd, at_force, node, par, w, nw, dir)
    ny = count(par(1:nw) == 0)
    nd = 0
    do comp = 1, 3
      do j = 1, ny
        nd = nd + 1; d(nd) = dof(node(j), comp); v(nd) = w(j)*dir(comp)
      end do
    end do
    do j = ny + 1, nw
      do comp = 1, 3
        nd = nd + 1; d(nd) = dof(node(j), 3 + comp); v(nd) = w(j)*dir(comp)
      end do
    end do
    if (kd /= 0 .or. a%nl == 0) return
    ! the lever D . dn on the positions n depends on: into the row's own entries where the
    ! node has them, after them where not (the same parameters for the gap and the force)
    do l = 1, a%nl
      if (at_force) then
        lg = a%lgradf(:, l)
      else
        lg = a%lgrad(:, l)
      end if
      i = findloc(node(1:ny), a%lnode(l), dim=1)
      if (i > 0) then
        do comp = 1, 3
          v((comp - 1)*ny + i) = v((comp - 1)*ny + i) + lg(comp)
        end do
      else
        do comp = 1, 3
          nd = nd + 1; d(nd) = dof(a%lnode(l), comp); v(nd) = lg(comp)
        end do
      end if
    end do
  end subroutine constraint_row

  !> Where con's force acts at configuration q (positions and fibres): the point xif of the
  !> target's face, T(xi) = sum_j N_j (Y_j - wg(2) G_j), on the line through the node's face
  !> point P = Y + wg(1) G along the gap's normal n: T(xif) + s n = P. The force pair,
  !> -lambda n on P and lambda n on T, then lies on one line and has no moment: taken where
  !> the scheme takes the internal force (the midpoint rule's q_mid), frictionless contact
  !> keeps the free bodies' angular momentum. Friction acts at the same two points: its
  !> moment, s n x f_t, is left by the separation s there, which a lasting contact closes
  !> at both ends of the step. (The gap's own point, held through the step,
  !> is half a step's slide away from the node there. The closest point of the face was
  !> tried first: it keeps L as well, but at a node shared by curved elements it is not
  !> unique, and pole-on-pole contact between spheres turned sideways.)
  !> Newton on (xi, s) from the gap's point; the polynomial face holds beyond the element's
  !> edge, so a point just outside is kept (its weights still sum to one); one not found
  !> keeps the gap's point (an obstacle's too).
  pure subroutine force_point(model, q, con)
    type(model_t), intent(in) :: model
    real(dp), intent(in) :: q(:)
    type(constraint_t), intent(inout) :: con
    real(dp) :: ye(3, 10), p(3), xi(2), shp(10), dphi(10, 2), j(3, 3), f(3), dx(2), det, out
    integer :: k, it, nd
    call hold_force_point(con)
    if (con%elem == 0) return
    do k = 1, 10
      nd = model%conn(k, con%elem)
      ye(:, k) = q(dof(nd, 1):dof(nd, 3)) - con%wg(2)*q(dof(nd, 4):dof(nd, 6))
    end do
    ! around a rim the node's line meets the face's polynomial beyond the edge, far out as
    ! n turns across the face: a point more than a sliver outside is the edge's instead
    out = beyond_element
    if (con%side == around_rim) out = -0.02_dp
    p = q(dof(con%node, 1):dof(con%node, 3)) + con%wg(1)*q(dof(con%node, 4):dof(con%node, 6))
    xi = con%xi
    dx = 1
    do it = 1, 20
      call tri10_shape(xi(1), xi(2), shp, dphi)
      j(:, 1:2) = matmul(ye, dphi); j(:, 3) = con%n
      f = p - matmul(ye, shp)   ! = J [dxi; s] to first order (s enters linearly)
      det = dot_product(j(:, 1), cross(j(:, 2), j(:, 3)))
      if (.not. abs(det) > 0) exit
      ! Cramer's rule for the two xi components only (s itself is not wanted)
      dx(1) = dot_product(f, cross(j(:, 2), j(:, 3)))/det
      dx(2) = dot_product(j(:, 1), cross(f, j(:, 3)))/det
      xi = xi + dx
      if (minval(area_coordinates(xi)) < out) exit
      if (maxval(abs(dx)) <= 1e-14_dp) exit
    end do
    if (maxval(abs(dx)) > 1e-12_dp .or. minval(area_coordinates(xi)) < out) then
      if (con%side == around_rim) call rim_force_point(ye, q(dof(con%node, 1):dof(con%node, 3)), con)
      return
    end if
    call tri10_shape(xi(1), xi(2), shp, dphi)
    con%xif = xi; con%shpf = shp
  end subroutine force_point

  !> The gradient lg(:, 1:nl) of dv . con%n on the positions of the nodes lnode(1:nl) that
  !> the target normal at con%xi depends on (con%side and xi held): the element's nodes, and
  !> with nodal normals those of every element at them. Reverse mode through
  !> n = u/|u|, u = sum_j N_j m_j/|m_j|, m_j = sum_e t_e/|t_e|, t_e = a1 x a2 (the cubic
  !> normal of element e at node j), gathered element by element. nl = 0 when the nodes
  !> outnumber max_lever (or the elements max_elem).
  subroutine normal_lever(c, model, x, con, dv, nl, lnode, lg, normals)
    type(contact_t), intent(in) :: c
    type(model_t), intent(in) :: model
    real(dp), intent(in) :: x(:, :), dv(3)
    type(constraint_t), intent(in) :: con
    integer, intent(out) :: nl, lnode(max_lever)
    real(dp), intent(out) :: lg(3, max_lever)
    type(normal_cache_t), intent(inout), optional :: normals   !< made by constraint_geometry
    integer, parameter :: max_elem = 64
    real(dp) :: shp(10), dphi(10, 2), u(3), bu(3), m(3, 10), bm(3), t(3), ge(3, 10, max_elem)
    integer :: j, i, nd, l, p, ne, el(max_elem)
    nl = 0; ne = 0
    call tri10_shape(con%xi(1), con%xi(2), shp, dphi)
    associate (g => c%geo)
      if (.not. c%opt%nodal_normal) then
        call back_normal(con%elem, dphi, con%side*dv)
      else
        u = 0
        do j = 1, 10   ! (forward, as constraint_geometry)
          call node_normal_sum(c, model, x, model%conn(j, con%elem), m(:, j), normals)
          u = u + (shp(j)/norm2(m(:, j)))*m(:, j)
        end do
        bu = u/norm2(u)
        bu = con%side*(dv - dot_product(dv, bu)*bu)/norm2(u)
        do j = 1, 10
          nd = model%conn(j, con%elem)
          t(1) = norm2(m(:, j)); m(:, j) = m(:, j)/t(1)
          bm = shp(j)*(bu - dot_product(bu, m(:, j))*m(:, j))/t(1)
          do i = g%node_start(nd), g%node_start(nd + 1) - 1
            call back_normal(g%node_elem(i), g%dphi_node(:, :, g%node_loc(i)), bm)
          end do
        end do
      end if
    end associate
    if (ne > max_elem) return
    do i = 1, ne   ! (the elements' gradients onto their nodes)
      do l = 1, 10
        nd = model%conn(l, el(i))
        p = findloc(lnode(1:nl), nd, dim=1)
        if (p == 0) then
          if (nl == max_lever) then
            nl = 0; return
          end if
          nl = nl + 1; lnode(nl) = nd; p = nl; lg(:, p) = 0
        end if
        lg(:, p) = lg(:, p) + ge(:, l, i)
      end do
    end do
  contains
    !> add the gradient of b . t/|t| (t element e's cubic normal where its shape
    !> derivatives are ds) on e's nodes
    subroutine back_normal(e, ds, b)
      integer, intent(in) :: e
      real(dp), intent(in) :: ds(10, 2), b(3)
      real(dp) :: a1(3), a2(3), tn(3), tl, bt(3), b1(3), b2(3)
      integer :: k, q
      if (ne > max_elem) return
      q = findloc(el(1:ne), e, dim=1)
      if (q == 0) then
        ne = ne + 1
        if (ne > max_elem) return
        el(ne) = e; q = ne; ge(:, :, q) = 0
      end if
      a1 = matmul(x(:, model%conn(:, e)), ds(:, 1)); a2 = matmul(x(:, model%conn(:, e)), ds(:, 2))
      tn = cross(a1, a2); tl = norm2(tn); tn = tn/tl
      bt = (b - dot_product(b, tn)*tn)/tl
      b1 = cross(a2, bt); b2 = cross(bt, a1)   ! b . (da1 x a2 + a1 x da2)
      do k = 1, 10
        ge(:, k, q) = ge(:, k, q) + ds(k, 1)*b1 + ds(k, 2)*b2
      end do
    end subroutine back_normal
  end subroutine normal_lever

  !> The unit normal of element e at its node k at positions x (normals: the cache, filled
  !> here where it was not made)
  function element_normal(c, model, x, e, k, normals) result(nk)
    type(contact_t), intent(in) :: c
    type(model_t), intent(in) :: model
    real(dp), intent(in) :: x(:, :)
    integer, intent(in) :: e, k
    type(normal_cache_t), intent(inout), optional :: normals
    real(dp) :: nk(3)
    if (present(normals)) then
      if (.not. normals%made(k, e)) then
        normals%n(:, k, e) = unit_normal(x(:, model%conn(:, e)), c%geo%dphi_node(:, :, k))
        normals%made(k, e) = .true.
      end if
      nk = normals%n(:, k, e)
    else
      nk = unit_normal(x(:, model%conn(:, e)), c%geo%dphi_node(:, :, k))
    end if
  end function element_normal

  !> m: the sum of the unit normals, at node nd, of every element there (the nodal normal's
  !> direction). The mesh's orientation is consistent (scene.f90 refuses one that is not), so
  !> each is taken as it is, as the fibres' sum at the start is (model.f90): each turned to
  !> one element's side by the sign of its dot product with that one's, the sides of a square
  !> tube's 90-degree crease were turned either way by round-off, and the normal there lay
  !> along the wall (a can's node 2.6 mm off the crease was taken as touching: Newton failed)
  subroutine node_normal_sum(c, model, x, nd, m, normals)
    type(contact_t), intent(in) :: c
    type(model_t), intent(in) :: model
    real(dp), intent(in) :: x(:, :)
    integer, intent(in) :: nd
    real(dp), intent(out) :: m(3)
    type(normal_cache_t), intent(inout), optional :: normals
    integer :: i
    m = 0
    do i = c%geo%node_start(nd), c%geo%node_start(nd + 1) - 1
      m = m + element_normal(c, model, x, c%geo%node_elem(i), c%geo%node_loc(i), normals)
    end do
  end subroutine node_normal_sum

  !> Around an open surface's rim the target is its edge, rounded by the faces' offsets: n
  !> from the mid-surface's point at xi to the node (r), across the edge's tangent te where
  !> xi is on one edge of the element (the tangent xe . tw, of length tl), the direction
  !> itself at a corner (te, tw, tl = 0): the node keeps its distance as it slides along the
  !> rim within a step (xi held), and beside the rim (r along the surface's normal) it is
  !> the face's gap.
  pure subroutine rim_normal(xe, dphi, xi, r, n, te, tw, tl, dxi)
    real(dp), intent(in) :: xe(3, 10), dphi(10, 2), xi(2), r(3)
    real(dp), intent(out) :: n(3), te(3), tw(10), tl
    real(dp), intent(out), optional :: dxi(2)   !< the edge's direction in xi (tw = dphi dxi)
    real(dp), parameter :: on_edge = 1e-9_dp
    real(dp) :: l(3), d(2)
    l = area_coordinates(xi)
    d = 0
    if (count(l < on_edge) == 1) then
      if (l(1) < on_edge) d = [0._dp, 1._dp]
      if (l(2) < on_edge) d = [1._dp, 0._dp]
      if (l(3) < on_edge) d = [1._dp, -1._dp]
    end if
    if (present(dxi)) dxi = d
    tw = matmul(dphi, d)
    te = matmul(xe, tw); tl = norm2(te)
    if (tl > 0) te = te/tl
    n = r - dot_product(r, te)*te
    if (norm2(n) > 0) then
      n = n/norm2(n)
    else   ! (on the edge itself: no direction)
      n = unit_normal(xe, dphi)
    end if
  end subroutine rim_normal

  !> Where the force of a constraint around a rim acts on the target where the node's line
  !> meets no point of the face within the element (force_point): the edge's
  !> point at the foot of the node's line along n, xi moved along the edge until
  !> r = Y - T(xi) lies across its tangent (at a corner, the held point). The pair then lies
  !> on one line but for the node's face offset across n (none where its fibre is along n
  !> or, at its own rim, edge-on), as the velocity correction's rows need: held at the
  !> gap's point, two rings meeting rim on rim lost 4e-7 of their angular momentum.
  pure subroutine rim_force_point(xe, y, con)
    real(dp), intent(in) :: xe(3, 10)   !< the target element's mid-surface points
    real(dp), intent(in) :: y(3)        !< the node's
    type(constraint_t), intent(inout) :: con
    real(dp) :: xi(2), shp(10), dphi(10, 2), n(3), te(3), tw(10), tl, dxi(2), r(3)
    integer :: it
    xi = con%xi
    do it = 1, 4
      call tri10_shape(xi(1), xi(2), shp, dphi)
      r = y - matmul(xe, shp)
      call rim_normal(xe, dphi, xi, r, n, te, tw, tl, dxi)
      if (.not. tl > 0) return
      xi = xi + (dot_product(te, r)/tl)*dxi
      if (minval(area_coordinates(xi)) < beyond_element) return
    end do
    call tri10_shape(xi(1), xi(2), shp, dphi)
    con%xif = xi; con%shpf = shp
  end subroutine rim_force_point

  !> The lever of a constraint around a rim (rim_normal): the gap n . r - offsets(n) has the
  !> derivative w . d(P r), w = n + (I - nn) f/|P r| (f = wg(1) G + wg(2) G_t, the offsets'
  !> derivative on n), P = I - te te, d(P r) = P dr - (dte . r) te - (te . r) dte, dte =
  !> (I - te te) dt/tl, dt = sum_j tw_j dx_j: beyond the row's n on the node and -N_j n on the
  !> target, P u on the node and -N_j P u - tw_j b on the target, u = (I - nn) f/|P r|,
  !> b = ((f . te) n + (te . r) P w)/tl. Exact for xi held, so the force has no moment.
  pure subroutine rim_lever(model, con, r, f, te, tw, tl)
    type(model_t), intent(in) :: model
    type(constraint_t), intent(inout) :: con
    real(dp), intent(in) :: r(3), f(3), te(3), tw(10), tl
    real(dp) :: gm, u(3), b(3), lg(3, 11)
    integer :: j, ln(11)
    con%nl = 0
    gm = dot_product(con%n, r)
    if (.not. gm > 0) return
    u = (f - dot_product(con%n, f)*con%n)/gm
    u = u - dot_product(u, te)*te
    b = 0
    if (tl > 0) b = (dot_product(f, te)*con%n + dot_product(te, r)*(con%n + u))/tl
    ln(1) = con%node; lg(:, 1) = u
    do j = 1, 10
      ln(1 + j) = model%conn(j, con%elem)
      lg(:, 1 + j) = -con%shp(j)*u - tw(j)*b
    end do
    call set_lever(con, ln, lg)
  end subroutine rim_lever

  !> The lever of con: the nodes ln its normal depends on and the gap's gradient lg on them
  pure subroutine set_lever(con, ln, lg)
    type(constraint_t), intent(inout) :: con
    integer, intent(in) :: ln(:)
    real(dp), intent(in) :: lg(:, :)
    con%nl = size(ln)
    con%lnode = ln; con%lgrad = lg   ! (reallocated only when nl changes)
  end subroutine set_lever

  !> The area coordinates of parent point xi (each is 0 on one edge of the element)
  pure function area_coordinates(xi) result(l)
    real(dp), intent(in) :: xi(2)
    real(dp) :: l(3)
    l = [xi(1), xi(2), 1 - xi(1) - xi(2)]
  end function area_coordinates

  !> The force acts at the gap's point until force_point finds its own
  pure subroutine hold_force_point(con)
    type(constraint_t), intent(inout) :: con
    con%xif = con%xi; con%shpf = con%shp; con%nf = con%n
    con%wgf = con%wg
    if (con%nl > 0) con%lgradf = con%lgrad(:, 1:con%nl)
  end subroutine hold_force_point

  !> Unit normal of the cubic surface with node positions xe where the shape derivatives are dphi
  pure function unit_normal(xe, dphi) result(n)
    real(dp), intent(in) :: xe(3, 10), dphi(10, 2)
    real(dp) :: n(3)
    n = tri10_normal(xe, dphi)
    n = n/norm2(n)
  end function unit_normal
end module casca_contact_projection
