!> One constraint's geometry: the target point of a node (nearest sub-triangle of the target,
!> or the closest point of an obstacle), and at that point the shape functions, the normal
!> and the gap between the faces.
!>
!> The faces lie at half the thickness from the mid-surface along the current fibre: the
!> element maps xi3 = +-1 to Y + (h0/2)(+-1 + a) G, so a face is (h0/2)(+-1 + a) G.n away
!> from the mid-surface along n. The offset is measured at the node and at the target point
!> and held in the linearisation, as n and xi are: Newton refreshes it with the point.
module casca_contact_projection
  use casca_kinds, only: dp
  use casca_model, only: model_t, dof
  use casca_shape_tri10, only: tri10_shape, tri10_normal
  use casca_vectors, only: cross
  use casca_surface_search, only: grid_build, nearest_subtriangle, subtri_parent_xi
  use casca_obstacle, only: obstacle_point
  use casca_contact, only: contact_t, constraint_t, search_radius
  implicit none
  private
  public :: positions, body_box, project, constraint_geometry, constraint_entries

contains

  !> The mid-surface positions (3, nnode) of q
  pure function positions(model, q) result(x)
    type(model_t), intent(in) :: model
    real(dp), intent(in) :: q(:)
    real(dp) :: x(3, model%nnode)
    integer :: n
    do n = 1, model%nnode
      x(:, n) = q(dof(n, 1):dof(n, 3))
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
      con%node = node; con%pair = p; con%elem = g%surf(bt)%elem(itri)
      call subtri_parent_xi(g%surf(bt), itri, bary, con%xi)
    end associate
  end subroutine project

  !> Shape functions, normal (towards the node's side), face offset and gap of con at its
  !> point; for an obstacle (con%elem = 0 on an obstacle pair) the point is found here.
  subroutine constraint_geometry(c, model, x, q, con)
    type(contact_t), intent(in) :: c
    type(model_t), intent(in) :: model
    real(dp), intent(in) :: x(:, :), q(:)
    type(constraint_t), intent(inout) :: con
    real(dp) :: dphi(10, 2), xt(3), xe(3, 10), own(3), m(3), ne(3), gm, gt(3), at, fi, ft
    integer :: j, i, nd, bi, bt
    bi = c%pair(1, con%pair); bt = c%pair(2, con%pair)
    if (bt <= 0) then
      con%elem = 0; con%side = 1; con%shp = 0
      call obstacle_point(c%obstacle(-bt), c%time, x(:, con%node), con%n, gm)
      con%off = 0; con%dg = 0
      if (c%faces) call face(model%body(bi)%thickness, q(dof(con%node, 4):dof(con%node, 6)), &
                             q(dof(con%node, 7)), -con%n, con%off, con%dg(1:2))
      con%dg(1) = -con%dg(1)   ! (the derivative along -n, turned to n)
      con%gap = gm - con%off
      return
    end if
    call tri10_shape(con%xi(1), con%xi(2), con%shp, dphi)
    xe = x(:, model%conn(:, con%elem))   ! gathered once for the point and both tangents
    xt = matmul(xe, con%shp)
    if (c%nodal_normal) then
      con%n = 0
      associate (g => c%geo)
        do j = 1, 10
          nd = model%conn(j, con%elem)
          own = unit_normal(xe, g%dphi_node(:, :, j))
          m = 0   ! the normals of the elements at node j, turned to this element's side
          do i = g%node_start(nd), g%node_start(nd + 1) - 1
            ne = unit_normal(x(:, model%conn(:, g%node_elem(i))), g%dphi_node(:, :, g%node_loc(i)))
            m = m + sign(1._dp, dot_product(ne, own))*ne
          end do
          con%n = con%n + (con%shp(j)/norm2(m))*m
        end do
      end associate
    else
      con%n = unit_normal(xe, dphi)
    end if
    con%n = con%n/norm2(con%n)
    gm = dot_product(x(:, con%node) - xt, con%n)
    ! between mid-surfaces the target is one-sided (the thesis: its normal's side); between
    ! faces a shell is two-sided and the node stays on the side it came from
    if (con%side == 0) then
      con%side = 1
      if (c%faces) con%side = int(sign(1._dp, gm))
    end if
    con%n = con%side*con%n
    con%off = 0; con%dg = 0
    if (c%faces) then
      gt = 0; at = 0
      do j = 1, 10
        nd = model%conn(j, con%elem)
        gt = gt + con%shp(j)*q(dof(nd, 4):dof(nd, 6))
        at = at + con%shp(j)*q(dof(nd, 7))
      end do
      ! the impactor's face towards the target (along -n), the target's towards the node
      call face(model%body(bi)%thickness, q(dof(con%node, 4):dof(con%node, 6)), q(dof(con%node, 7)), &
                -con%n, fi, con%dg(1:2))
      call face(model%body(bt)%thickness, gt, at, con%n, ft, con%dg(3:4))
      con%dg(1) = -con%dg(1)
      con%off = fi + ft
    end if
    con%gap = con%side*gm - con%off
  end subroutine constraint_geometry

  !> Distance f along u of the face that lies farthest along u: max over s = +-1 of
  !> (h/2)(s + a) G.u = (h/2)(|G.u| + a G.u), and its derivatives: df = d(1) u.dG + d(2) da
  pure subroutine face(h, g, a, u, f, d)
    real(dp), intent(in) :: h, g(3), a, u(3)
    real(dp), intent(out) :: f, d(2)
    real(dp) :: k
    k = dot_product(g, u)
    f = 0.5_dp*h*(abs(k) + a*k)
    d = 0.5_dp*h*[sign(1._dp, k) + a, k]
  end subroutine face

  !> The nodes a constraint acts on and the weights of its row of C: n on the impactor node,
  !> -N_j n on the target element's nodes (none for an obstacle). m: how many.
  pure subroutine constraint_entries(con, model, nodes, w, m)
    type(constraint_t), intent(in) :: con
    type(model_t), intent(in) :: model
    integer, intent(out) :: nodes(11), m
    real(dp), intent(out) :: w(11)
    nodes(1) = con%node; w(1) = 1
    m = 1
    if (con%elem == 0) return
    nodes(2:) = model%conn(:, con%elem); w(2:) = -con%shp
    m = 11
  end subroutine constraint_entries

  !> Unit normal of the cubic surface with node positions xe where the shape derivatives are dphi
  pure function unit_normal(xe, dphi) result(n)
    real(dp), intent(in) :: xe(3, 10), dphi(10, 2)
    real(dp) :: n(3)
    n = tri10_normal(xe, dphi)
    n = n/norm2(n)
  end function unit_normal
end module casca_contact_projection
