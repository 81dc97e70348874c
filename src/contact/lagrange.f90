!> Non-penetration by Lagrange multipliers (thesis ch. 5). For each pair (impactor body,
!> target body), every impactor node whose signed distance to the target's sub-triangles is
!> negative gets one multiplier lambda and the condition
!>     g = (x_imp - x_target(xi)) . n(xi) = 0,   x_target = N_j(xi) Y^j of the cubic element,
!> with n the unit normal of the target at xi, linearised with xi and n held (eq. 5.6). The
!> thesis takes the cubic element's own normal (eq. 5.4, normal = 'element'), which jumps
!> across element edges: a node pressed onto an edge or a vertex is pushed sideways, onto the
!> neighbour, and back, step after step. By default (normal = 'nodal') n interpolates nodal
!> normals averaged over the elements at each node, continuous over the surface.
!> lambda < 0 is compression (the contact force on the impactor is -lambda n); a multiplier
!> that turns tensile at convergence is released.
module casca_contact
  use casca_kinds, only: dp
  use casca_model, only: model_t, dof
  use casca_shape_tri10, only: tri10_shape, tri10_normal, tri10_node_xi
  use casca_vectors, only: cross
  use casca_surface_search, only: surface_t, grid_t, surface_init, grid_build, &
                                  nearest_subtriangle, subtri_parent_xi
  implicit none
  private
  public :: contact_t, constraint_t, contact_init, contact_update, contact_release, contact_rows
  public :: contact_penetration, contact_force_total, contact_nodal_fields, contact_signed_distance

  type :: constraint_t
    integer :: node = 0, pair = 0, elem = 0
    real(dp) :: xi(2) = 0, n(3) = 0, shp(10) = 0
    real(dp) :: gap = 0, lambda = 0
    real(dp) :: sd = 0          !< signed distance to the sub-triangles when last projected
    real(dp) :: mu = 0          !< the acceleration's correction: M a += C^T mu (after a step)
  end type constraint_t

  type :: contact_t
    integer :: npairs = 0
    integer, allocatable :: pair(:, :)          !< (2, npairs) impactor body, target body
    type(surface_t), allocatable :: surf(:)     !< per body (only targets are built)
    type(grid_t), allocatable :: grid(:)        !< per pair: the target near the impactor
    logical, allocatable :: grid_ok(:)          !< grid of this pair rebuilt for this q
    real(dp), allocatable :: depth(:)           !< per body: deepest signed distance taken as penetration
    real(dp) :: tol = 0                         !< penetration accepted [m]
    integer :: nact = 0
    type(constraint_t), allocatable :: act(:)
    integer :: changes = 0                      !< active-set changes in this step
    logical :: nodal_normal = .true.            !< n from nodal normals, else the element's
    ! the target elements at node n: node_elem(node_start(n) : node_start(n+1) - 1), and which
    ! of their nodes n is (node_loc); shape derivatives at the 10 nodes (dphi_node)
    integer, allocatable :: node_start(:), node_elem(:), node_loc(:)
    real(dp) :: dphi_node(10, 2, 10) = 0
  end type contact_t

contains

  !> pairs(2, npairs): impactor and target body of each pair. tol: accepted penetration [m].
  subroutine contact_init(model, pairs, tol, c)
    type(model_t), intent(in) :: model
    integer, intent(in) :: pairs(:, :)
    real(dp), intent(in) :: tol
    type(contact_t), intent(out) :: c
    integer :: b, e, k, n
    real(dp) :: edge, phi(10)
    logical, allocatable :: target_elem(:)
    c%npairs = size(pairs, 2)
    c%pair = pairs
    c%tol = tol
    allocate (c%surf(model%nbody), c%grid(c%npairs), c%grid_ok(c%npairs), &
              c%depth(model%nbody), c%act(16))
    c%grid_ok = .false.; c%depth = 0
    do b = 1, model%nbody
      if (.not. any(pairs(2, :) == b)) cycle
      associate (bd => model%body(b))
        call surface_init(model%conn, [(e, e=bd%elem_first, bd%elem_last)], c%surf(b))
        ! half the mean sub-triangle edge: a node deeper than that is behind the surface,
        ! not through it (matters at the rim of open surfaces)
        edge = 0
        do k = 1, c%surf(b)%ntri
          edge = edge + norm2(model%x0(:, c%surf(b)%tri(1, k)) - model%x0(:, c%surf(b)%tri(2, k)))
        end do
        c%depth(b) = 0.5_dp*edge/c%surf(b)%ntri
      end associate
    end do
    ! the elements of the targets at each node (counted, then filled)
    allocate (target_elem(model%nelem), c%node_start(model%nnode + 1))
    target_elem = .false.
    do b = 1, model%nbody
      if (any(pairs(2, :) == b)) target_elem(model%body(b)%elem_first:model%body(b)%elem_last) = .true.
    end do
    c%node_start = 0
    do e = 1, model%nelem
      if (target_elem(e)) c%node_start(model%conn(:, e) + 1) = c%node_start(model%conn(:, e) + 1) + 1
    end do
    c%node_start(1) = 1
    do n = 1, model%nnode
      c%node_start(n + 1) = c%node_start(n + 1) + c%node_start(n)
    end do
    allocate (c%node_elem(c%node_start(model%nnode + 1) - 1), c%node_loc(c%node_start(model%nnode + 1) - 1))
    do e = 1, model%nelem
      if (.not. target_elem(e)) cycle
      do k = 1, 10
        n = model%conn(k, e)
        c%node_elem(c%node_start(n)) = e; c%node_loc(c%node_start(n)) = k
        c%node_start(n) = c%node_start(n) + 1
      end do
    end do
    c%node_start(2:) = c%node_start(1:model%nnode); c%node_start(1) = 1
    do k = 1, 10
      call tri10_shape(tri10_node_xi(1, k), tri10_node_xi(2, k), phi, c%dphi_node(:, :, k))
    end do
  end subroutine contact_init

  !> Refresh the active constraints (normal and gap at their point; with reproject, the point
  !> itself: nearest sub-triangle again) and, with detect, add the penetrating nodes that are
  !> not yet active. Holding the point in late Newton iterations avoids flip-flopping between
  !> two elements at a kink of the C0 surface. Returns the number of constraints added.
  subroutine contact_update(c, model, q, detect, added, reproject)
    type(contact_t), intent(inout) :: c
    type(model_t), intent(in) :: model
    real(dp), intent(in) :: q(:)
    logical, intent(in) :: detect
    integer, intent(out) :: added
    logical, intent(in), optional :: reproject
    real(dp), allocatable :: x(:, :)
    real(dp) :: boxi(3, 2), boxt(3, 2), sd
    integer :: ip, bi, bt, n, k
    logical :: found
    type(constraint_t) :: cn

    added = 0
    allocate (x(3, model%nnode))
    x = positions(model, q)
    c%grid_ok = .false.
    ! active constraints: project again (the target moves and the node slides)
    do k = 1, c%nact
      found = .false.
      if (c%act(k)%elem > 0 .and. present(reproject)) then
        if (.not. reproject) then
          call finish(c%act(k)); cycle
        end if
      end if
      call project(c%act(k)%node, c%act(k)%pair, cn, sd, found)
      if (found) then
        call finish(cn)
        cn%lambda = c%act(k)%lambda
        c%act(k) = cn
      else   ! far from every sub-triangle within the band: keep the last projection
        call finish(c%act(k))
      end if
    end do
    if (.not. detect) return
    do ip = 1, c%npairs
      bi = c%pair(1, ip); bt = c%pair(2, ip)
      boxi = box_of(bi); boxt = box_of(bt)
      ! bodies whose boxes (the target's grown by the penetration band) are apart cost nothing
      if (any(boxi(:, 1) > boxt(:, 2) + c%depth(bt)) .or. any(boxi(:, 2) < boxt(:, 1) - c%depth(bt))) cycle
      do n = model%body(bi)%node_first, model%body(bi)%node_last
        if (any(x(:, n) > boxt(:, 2) + c%depth(bt)) .or. any(x(:, n) < boxt(:, 1) - c%depth(bt))) cycle
        if (is_active(n, ip)) cycle
        call project(n, ip, cn, sd, found)
        if (.not. found) cycle
        ! the sub-triangles are chords of the cubic surface: they find the candidates, the
        ! constraint's own gap decides (else a node released with zero gap would be taken
        ! again at once where the chord lies outside the surface). A cubic arc bulges from
        ! its chord e by kappa e^2 / 8, below a quarter of depth = e / 2 while kappa e < 1
        if (sd >= 0.25_dp*c%depth(c%pair(2, ip)) .or. .not. has_free_position(n, cn%elem)) cycle
        call finish(cn)
        if (cn%gap < -c%tol) then
          call push(cn)
          added = added + 1
        end if
      end do
    end do
    if (added > 0) c%changes = c%changes + 1
  contains
    function box_of(b) result(bx)
      integer, intent(in) :: b
      real(dp) :: bx(3, 2)
      associate (bd => model%body(b))
        bx(:, 1) = minval(x(:, bd%node_first:bd%node_last), dim=2)
        bx(:, 2) = maxval(x(:, bd%node_first:bd%node_last), dim=2)
      end associate
    end function box_of

    logical function is_active(node, p)
      integer, intent(in) :: node, p
      integer :: j
      is_active = .false.
      do j = 1, c%nact
        if (c%act(j)%node == node .and. c%act(j)%pair == p) then
          is_active = .true.; return
        end if
      end do
    end function is_active

    !> a constraint needs at least one free position on either side
    logical function has_free_position(node, e)
      integer, intent(in) :: node, e
      has_free_position = .not. (all(model%fixed(dof(node, 1):dof(node, 3))) .and. &
                            all(model%fixed(dof(model%conn(:, e), 1))) .and. &
                            all(model%fixed(dof(model%conn(:, e), 2))) .and. &
                            all(model%fixed(dof(model%conn(:, e), 3))))
    end function has_free_position

    !> signed distance of node to the target of pair p, and the point of the constraint it
    !> would carry (finish gives its normal and gap)
    subroutine project(node, p, con, sdist, ok)
      integer, intent(in) :: node, p
      type(constraint_t), intent(out) :: con
      real(dp), intent(out) :: sdist
      logical, intent(out) :: ok
      integer :: b, itri, region
      real(dp) :: xq(3), bary(3), dist, nt(3), near(3, 2)
      b = c%pair(2, p)
      if (.not. c%grid_ok(p)) then   ! the target's sub-triangles within reach of the impactor
        near = box_of(c%pair(1, p))
        near(:, 1) = near(:, 1) - c%depth(b); near(:, 2) = near(:, 2) + c%depth(b)
        call grid_build(c%surf(b), x, c%grid(p), near)
        c%grid_ok(p) = .true.
      end if
      call nearest_subtriangle(c%surf(b), c%grid(p), x, x(:, node), c%depth(b), ok, itri, xq, &
                               bary, dist, region)
      sdist = huge(1._dp)
      if (.not. ok) return
      associate (t => c%surf(b)%tri(:, itri))
        nt = cross(x(:, t(2)) - x(:, t(1)), x(:, t(3)) - x(:, t(1)))
      end associate
      sdist = sign(dist, dot_product(x(:, node) - xq, nt))
      con%sd = sdist
      con%node = node; con%pair = p; con%elem = c%surf(b)%elem(itri)
      call subtri_parent_xi(c%surf(b), itri, bary, con%xi)
    end subroutine project

    !> shape functions, normal and gap at the constraint's xi
    subroutine finish(con)
      type(constraint_t), intent(inout) :: con
      real(dp) :: dphi(10, 2), xt(3), xe(3, 10), own(3), m(3), ne(3)
      integer :: j, i, nd
      call tri10_shape(con%xi(1), con%xi(2), con%shp, dphi)
      xe = x(:, model%conn(:, con%elem))   ! gathered once for the point and both tangents
      xt = matmul(xe, con%shp)
      if (c%nodal_normal) then
        con%n = 0
        do j = 1, 10
          nd = model%conn(j, con%elem)
          own = unit_normal(xe, c%dphi_node(:, :, j))
          m = 0   ! the normals of the elements at node j, turned to this element's side
          do i = c%node_start(nd), c%node_start(nd + 1) - 1
            ne = unit_normal(x(:, model%conn(:, c%node_elem(i))), c%dphi_node(:, :, c%node_loc(i)))
            m = m + sign(1._dp, dot_product(ne, own))*ne
          end do
          con%n = con%n + (con%shp(j)/norm2(m))*m
        end do
      else
        con%n = unit_normal(xe, dphi)
      end if
      con%n = con%n/norm2(con%n)
      con%gap = dot_product(x(:, con%node) - xt, con%n)
    end subroutine finish

    subroutine push(con)
      type(constraint_t), intent(in) :: con
      type(constraint_t), allocatable :: tmp(:)
      if (c%nact == size(c%act)) then
        allocate (tmp(2*size(c%act)))
        tmp(1:c%nact) = c%act(1:c%nact)
        call move_alloc(tmp, c%act)
      end if
      c%nact = c%nact + 1
      c%act(c%nact) = con
    end subroutine push
  end subroutine contact_update

  !> Release the constraints whose multiplier is tensile (lambda > 0); how many were released.
  subroutine contact_release(c, released)
    type(contact_t), intent(inout) :: c
    integer, intent(out) :: released
    integer :: k, m
    m = 0
    do k = 1, c%nact
      if (c%act(k)%lambda > 0) cycle
      m = m + 1
      c%act(m) = c%act(k)
    end do
    released = c%nact - m
    c%nact = m
    if (released > 0) c%changes = c%changes + 1
  end subroutine contact_release

  !> Constraint rows for MUMPS: entries (neq + k, eq) of dg_k/dq (irn > jcn), a zero
  !> diagonal for each multiplier, and the gaps.
  subroutine contact_rows(c, model, eq, neq, irn, jcn, val, gap)
    type(contact_t), intent(in) :: c
    type(model_t), intent(in) :: model
    integer, intent(in) :: eq(:), neq
    integer, allocatable, intent(out) :: irn(:), jcn(:)
    real(dp), allocatable, intent(out) :: val(:), gap(:)
    integer :: k, j, comp, m, e
    allocate (irn(34*c%nact), jcn(34*c%nact), val(34*c%nact), gap(c%nact))
    m = 0
    do k = 1, c%nact
      associate (a => c%act(k))
        gap(k) = a%gap
        do comp = 1, 3
          call put(neq + k, eq(dof(a%node, comp)), a%n(comp))
          do j = 1, 10
            e = model%conn(j, a%elem)
            call put(neq + k, eq(dof(e, comp)), -a%shp(j)*a%n(comp))
          end do
        end do
        m = m + 1; irn(m) = neq + k; jcn(m) = neq + k; val(m) = 0
      end associate
    end do
    irn = irn(1:m); jcn = jcn(1:m); val = val(1:m)
  contains
    subroutine put(i, j2, v)
      integer, intent(in) :: i, j2
      real(dp), intent(in) :: v
      if (j2 == 0) return   ! prescribed parameter: no column
      m = m + 1; irn(m) = i; jcn(m) = j2; val(m) = v
    end subroutine put
  end subroutine contact_rows

  !> Deepest penetration of the impactor nodes that carry no constraint (signed distance to
  !> the sub-triangles) and largest |gap| of those that do.
  subroutine contact_penetration(c, model, q, free_pen, max_gap)
    type(contact_t), intent(in) :: c
    type(model_t), intent(in) :: model
    real(dp), intent(in) :: q(:)
    real(dp), intent(out) :: free_pen, max_gap
    type(contact_t) :: probe
    integer :: added, k
    ! a probe with no active constraint and zero tolerance detects every penetrating node
    call new_probe(c, 0._dp, probe)
    call contact_update(probe, model, q, .true., added, .false.)
    free_pen = 0
    do k = 1, probe%nact
      if (any(c%act(1:c%nact)%node == probe%act(k)%node .and. &
              c%act(1:c%nact)%pair == probe%act(k)%pair)) cycle
      free_pen = max(free_pen, -probe%act(k)%gap)
    end do
    max_gap = 0
    if (c%nact > 0) max_gap = maxval(abs(c%act(1:c%nact)%gap))
  end subroutine contact_penetration

  !> Signed distance of every impactor node to its target (the band's depth where farther,
  !> 0 for nodes that impact nothing), for output.
  subroutine contact_signed_distance(c, model, q, sd)
    type(contact_t), intent(in) :: c
    type(model_t), intent(in) :: model
    real(dp), intent(in) :: q(:)
    real(dp), intent(out) :: sd(:)
    type(contact_t) :: probe
    integer :: added, k, ip, b
    sd = 0
    do ip = 1, c%npairs
      b = c%pair(1, ip)
      sd(model%body(b)%node_first:model%body(b)%node_last) = c%depth(c%pair(2, ip))
    end do
    ! every node inside the band, penetrating or not: a probe that takes any distance
    call new_probe(c, -huge(1._dp), probe)
    call contact_update(probe, model, q, .true., added, .false.)
    do k = 1, probe%nact
      sd(probe%act(k)%node) = min(sd(probe%act(k)%node), probe%act(k)%sd)
    end do
  end subroutine contact_signed_distance

  !> The geometry of c with no constraint and tolerance tol (for the diagnostics above).
  subroutine new_probe(c, tol, probe)
    type(contact_t), intent(in) :: c
    real(dp), intent(in) :: tol
    type(contact_t), intent(out) :: probe
    probe%npairs = c%npairs; probe%pair = c%pair; probe%surf = c%surf; probe%depth = c%depth
    probe%node_start = c%node_start; probe%node_elem = c%node_elem; probe%node_loc = c%node_loc
    probe%dphi_node = c%dphi_node
    allocate (probe%grid(c%npairs), probe%grid_ok(c%npairs), probe%act(16))
    probe%grid_ok = .false.
    probe%tol = tol
    probe%nodal_normal = c%nodal_normal   ! the gaps as the constraints measure them
  end subroutine new_probe

  !> Total normal contact force (sum of the compressive multipliers).
  pure real(dp) function contact_force_total(c)
    type(contact_t), intent(in) :: c
    contact_force_total = -sum(c%act(1:c%nact)%lambda)
  end function contact_force_total

  !> Nodal contact force (3, nnode) on both sides, for output.
  pure subroutine contact_nodal_fields(c, model, force)
    type(contact_t), intent(in) :: c
    type(model_t), intent(in) :: model
    real(dp), intent(out) :: force(:, :)
    integer :: k, j
    force = 0
    do k = 1, c%nact
      associate (a => c%act(k))
        force(:, a%node) = force(:, a%node) - a%lambda*a%n
        do j = 1, 10
          force(:, model%conn(j, a%elem)) = force(:, model%conn(j, a%elem)) + a%lambda*a%shp(j)*a%n
        end do
      end associate
    end do
  end subroutine contact_nodal_fields

  !> Unit normal of the cubic surface with node positions xe where the shape derivatives are dphi
  pure function unit_normal(xe, dphi) result(n)
    real(dp), intent(in) :: xe(3, 10), dphi(10, 2)
    real(dp) :: n(3)
    n = tri10_normal(xe, dphi)
    n = n/norm2(n)
  end function unit_normal

  pure function positions(model, q) result(x)
    type(model_t), intent(in) :: model
    real(dp), intent(in) :: q(:)
    real(dp) :: x(3, model%nnode)
    integer :: n
    do n = 1, model%nnode
      x(:, n) = q(dof(n, 1):dof(n, 3))
    end do
  end function positions

end module casca_contact
