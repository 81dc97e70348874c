!> From a checked deck to the model: meshes (generated or read), materials, restraints,
!> loads, the initial state and the tracked nodes. Problems are added to the deck's list.
module casca_scene
  use casca_kinds, only: dp
  use casca_error, only: error_t
  use casca_mesh, only: mesh_t
  use casca_mesh_generators, only: generated_mesh
  use casca_gmsh_io, only: read_gmsh
  use casca_deck, only: deck_t, add_problem, deck_file, unset
  use casca_sanity, only: parse_fix
  use casca_model, only: model_t, model_add_body, model_finalize, dof, reference_state, &
                         element_area
  use casca_node_selection, only: body_sets_t, select_nodes, edge_shares, selected_elements
  use casca_newmark, only: state_t
  use casca_vectors, only: cross
  use casca_obstacle, only: obstacle_t
  use casca_contact, only: contact_t, contact_init, contact_set_stiffness
  use casca_orientation, only: reverse_elements, edge_census_t, edge_census, coincident_t, &
                               coincident_nodes, shortest_edge
  use casca_strings, only: itoa, rtoa, vtoa, count_of
  use casca_mpi, only: is_root
  implicit none
  private
  public :: build_model, initial_state, tracked_nodes, body_mesh, contact_pairs, scene_obstacles, &
            scene_contact, area_per_node, clearly

  !> One body's nodes are clearly denser than another's when its area per node is this many
  !> times smaller (impacts_first)
  real(dp), parameter :: clearly = 1.2_dp

contains

  !> The mesh of body ib as the deck describes it, moved to its centre (and with flip_normals
  !> its elements reversed, exact normals too).
  subroutine body_mesh(deck, ib, mesh, err)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: ib
    type(mesh_t), intent(out) :: mesh
    type(error_t), allocatable, intent(out) :: err
    integer :: i
    real(dp) :: rot(3, 3)
    associate (b => deck%bodies(ib))
      if (b%mesh == 'file') then
        call read_gmsh(deck_file(deck, b%file), mesh, err)
      else
        call generated_mesh(b, mesh, err)
      end if
      if (allocated(err)) return
      if (b%flip_normals) then
        call reverse_elements(mesh%conn)
        mesh%normal = -mesh%normal
      end if
      rot = rotation(b%rotate_axis, b%rotate_angle*acos(-1._dp)/180)
      do i = 1, mesh%nnode
        mesh%x(:, i) = matmul(rot, mesh%x(:, i)) + b%center
      end do
      if (size(mesh%normal, 2) == mesh%nnode) mesh%normal = matmul(rot, mesh%normal)
    end associate
  end subroutine body_mesh

  !> A problem if neighbouring elements of body ib's mesh disagree on its orientation: their
  !> normals would cancel in the averaged fibres (which then fail as 'degenerate' elements).
  subroutine check_orientation(deck, ib, mesh)
    type(deck_t), intent(inout) :: deck
    integer, intent(in) :: ib
    type(mesh_t), intent(in) :: mesh
    type(edge_census_t) :: ec
    ec = edge_census(mesh%conn, mesh%nnode)
    if (ec%disagree == 0) return
    call add_problem(deck, deck%bodies(ib)%line, '&body '//trim(deck%bodies(ib)%name)// &
      ': the mesh''s triangles are not consistently oriented: elements '//itoa(ec%elem(1))// &
      ' and '//itoa(ec%elem(2))//' traverse their shared edge (nodes '//itoa(ec%node(1))//', '// &
      itoa(ec%node(2))//') in the same direction ('//itoa(ec%disagree)//' such edges); '// &
      'the fibres, averaged from the element normals, would cancel there. Reorient the mesh '// &
      '(Gmsh: ReverseMesh Surface{...}; on the surfaces that disagree)')
  end subroutine check_orientation

  !> A warning (stderr, rank 0: casca check and casca run both build the model here) if body
  !> ib's mesh has distinct nodes at one position: surfaces meshed without their shared
  !> curves merged, which meet there unconnected (a seam: a slit if meant, else the parts
  !> hinge or fall apart there, and a static run fails as if it buckled). Within 1e-6 of the
  !> shortest edge between vertex nodes: a sound element's nodes lie a third of it apart at
  !> least, 3e5 times more, and coordinates written to 16 digits (Gmsh) differ by round-off
  !> only, 1e-16 of the scene's size.
  subroutine check_seams(deck, ib, mesh)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: ib
    type(mesh_t), intent(in) :: mesh
    type(coincident_t) :: cn
    real(dp) :: l_min
    integer :: e
    l_min = huge(1._dp)
    do e = 1, mesh%nelem
      l_min = min(l_min, shortest_edge(mesh%x(:, mesh%conn(1:3, e))))
    end do
    cn = coincident_nodes(mesh%x, 1e-6_dp*l_min)
    if (cn%pairs == 0 .or. .not. is_root()) return
    write (0, '(a)') 'warning: body '''//trim(deck%bodies(ib)%name)//''': its mesh has '// &
      count_of(cn%pairs, 'pair', 'pairs')//' of distinct nodes at the same position (within '// &
      rtoa(1e-6_dp*l_min)//' m), e.g. nodes '//itoa(cn%node(1))//' and '//itoa(cn%node(2))// &
      ' at '//vtoa(mesh%x(:, cn%node(1)))//': the surfaces there are not connected, a seam (a '// &
      'slit if meant; else the parts hinge or come apart there, and a static run fails as if '// &
      'it buckled). To join them, build the surfaces on shared points and curves (Gmsh''s '// &
      'built-in kernel merges coinciding ones with Geometry.AutoCoherence = 1, its default, or '// &
      'Coherence; gmsh.model.geo.removeAllDuplicates(); OpenCASCADE: BooleanFragments, '// &
      'gmsh.model.occ.removeAllDuplicates()), or merge the mesh''s nodes before saving it '// &
      '(Coherence Mesh; gmsh.model.mesh.removeDuplicateNodes())'
  end subroutine check_seams

  !> Rodrigues' rotation matrix (identity for a zero angle).
  pure function rotation(axis, angle) result(r)
    real(dp), intent(in) :: axis(3), angle
    real(dp) :: r(3, 3), k(3, 3), n(3)
    integer :: i
    r = 0
    do i = 1, 3
      r(i, i) = 1
    end do
    if (angle == 0) return
    n = axis/norm2(axis)
    k = reshape([0._dp, n(3), -n(2), -n(3), 0._dp, n(1), n(2), -n(1), 0._dp], [3, 3])
    r = r + sin(angle)*k + (1 - cos(angle))*matmul(k, k)
  end function rotation

  subroutine build_model(deck, model)
    type(deck_t), intent(inout) :: deck
    type(model_t), intent(out) :: model
    type(mesh_t) :: mesh
    type(error_t), allocatable :: err
    logical :: comps(7), ok
    integer :: ib, i, n, c, k
    integer, allocatable :: sel(:), elems(:)
    real(dp), allocatable :: share(:)
    type(body_sets_t) :: sets(size(deck%bodies))

    do ib = 1, size(deck%bodies)
      call body_mesh(deck, ib, mesh, err)
      if (allocated(err)) then
        call add_problem(deck, deck%bodies(ib)%line, '&body '//trim(deck%bodies(ib)%name)// &
                         ': '//err%message)
        cycle
      end if
      if (mesh%nelem == 0) then
        call add_problem(deck, deck%bodies(ib)%line, '&body '//trim(deck%bodies(ib)%name)// &
                         ': the mesh has no 10-node triangle')
        cycle
      end if
      call check_orientation(deck, ib, mesh)
      call check_seams(deck, ib, mesh)
      call check_thickness(deck, ib, mesh)
      if (allocated(mesh%sets)) then
        call move_alloc(mesh%sets, sets(ib)%sets)
      else
        allocate (sets(ib)%sets(0))   ! (generated meshes have no named sets)
      end if
      associate (b => deck%bodies(ib))
        call model_add_body(model, trim(b%name), mesh, b%young, b%poisson, b%density, b%thickness)
      end associate
    end do
    if (deck%nproblems > 0) return
    call model_finalize(model, err, ib)
    if (allocated(err) .and. ib == 0) then
      call add_problem(deck, 0, err%message); return
    else if (allocated(err)) then   ! (an element of ib's mesh: said as the mesh reader says it)
      associate (b => deck%bodies(ib))
        if (b%mesh == 'file') err%message = deck_file(deck, b%file)//': '//err%message
        call add_problem(deck, b%line, '&body '//trim(b%name)//': '//err%message); return
      end associate
    end if

    do i = 1, size(deck%restraints)
      associate (r => deck%restraints(i))
        call select_nodes(model, sets, '&restraint', r%body, r%nodes, r%set, r%box_min, r%box_max, &
                          sel, err)
        if (allocated(err)) then
          call add_problem(deck, r%line, err%message); cycle
        end if
        call parse_fix(r%fix, comps, ok)
        do c = 1, 7
          if (comps(c)) model%fixed(dof(sel, c)) = .true.
        end do
      end associate
    end do
    do i = 1, size(deck%loads)
      associate (l => deck%loads(i))
        call select_nodes(model, sets, '&load', l%body, l%nodes, l%set, l%box_min, l%box_max, &
                          sel, err)
        if (.not. allocated(err) .and. l%kind == 'pressure') then   ! (whole elements, no force)
          call selected_elements(model, '&load', sel, elems, err)
          if (.not. allocated(err)) then
            model%pressure(elems) = model%pressure(elems) + l%pressure
            cycle
          end if
        else if (.not. allocated(err)) then
          if (l%kind == 'edge') then
            call edge_shares(model, '&load', sel, share, err)
          else
            share = [(1._dp/size(sel), n=1, size(sel))]
          end if
        end if
        if (allocated(err)) then
          call add_problem(deck, l%line, err%message); cycle
        end if
        do n = 1, size(sel)
          model%fext(dof(sel(n), 1):dof(sel(n), 3)) = model%fext(dof(sel(n), 1):dof(sel(n), 3)) &
                                                      + share(n)*l%force
          model%moment(:, sel(n)) = model%moment(:, sel(n)) + share(n)*l%moment
        end do
        call check_drilling(deck, l%line, model, sel)
      end associate
    end do
    do k = 1, model%nbody
      model%body(k)%gravity = deck%run%gravity + deck%bodies(k)%gravity
    end do
    ! (a linear analysis' tangent is the stiffness unstressed: no load stiffness)
    model%load_stiffness = deck%run%load_stiffness .and. .not. deck%run%linear
    model%linear = deck%run%linear
    call closed_pressures(model)
  end subroutine build_model

  !> A shell node has no rotation about its fibre: a moment with a part along a loaded node's
  !> fibre (beyond 1%, round-off of nodal normals on a curved edge) is refused, naming it
  subroutine check_drilling(deck, line, model, sel)
    type(deck_t), intent(inout) :: deck
    integer, intent(in) :: line, sel(:)
    type(model_t), intent(in) :: model
    real(dp) :: m(3)
    integer :: k, n
    do k = 1, size(sel)
      n = sel(k); m = model%moment(:, n)
      if (abs(dot_product(m, model%v0(:, n))) <= 1e-2_dp*norm2(m)) cycle
      call add_problem(deck, line, '&load: moment: node '//itoa(n - model%body(model%node_body(n))%node_first + 1)// &
        ' of body "'//model%body(model%node_body(n))%name//'" takes '//vtoa(m)// &
        ' N m, with a part along its normal '//vtoa(model%v0(:, n))// &
        ': a shell carries no moment about its normal (drilling); give the moment across it')
      return
    end do
  end subroutine check_drilling

  !> a thickness above half its body's size is no shell: a length in another unit (2 for
  !> 0.002 on a ball of 0.05 m weighed 66 t and ran). Judged on the mesh, before the elements
  !> are set up: thicker than its radius of curvature, a ring turns inside out through its
  !> thickness, and was refused as a degenerate element, with no line
  subroutine check_thickness(deck, ib, mesh)
    type(deck_t), intent(inout) :: deck
    integer, intent(in) :: ib
    type(mesh_t), intent(in) :: mesh
    real(dp) :: extent
    associate (b => deck%bodies(ib))
      extent = maxval(maxval(mesh%x, dim=2) - minval(mesh%x, dim=2))
      if (b%thickness > 0.5_dp*extent) call add_problem(deck, b%line, '&body '//trim(b%name)// &
        ': thickness '//rtoa(b%thickness)//' m is more than half the body''s size, '//rtoa(extent)// &
        ' m: no shell is that thick (a length in another unit?)')
    end associate
  end subroutine check_thickness

  !> model%pressure_closed: per body, its loaded elements carry one pressure and every edge of
  !> theirs is shared by exactly two of them, traversed both ways (no rim, branch or flip).
  !> Only there is the follower pressure conservative whatever the restraints, with the
  !> potential -p V: elsewhere the element volumes' rim terms depend on the origin.
  subroutine closed_pressures(model)
    type(model_t), intent(inout) :: model
    type(edge_census_t) :: ec
    integer, allocatable :: loaded(:)
    integer :: k, e
    do k = 1, model%nbody
      associate (b => model%body(k))
        loaded = pack([(e, e=b%elem_first, b%elem_last)], model%pressure(b%elem_first:b%elem_last) /= 0)
        if (size(loaded) == 0) cycle
        if (any(model%pressure(loaded) /= model%pressure(loaded(1)))) cycle
        ec = edge_census(model%conn(:, loaded), model%nnode)
        model%pressure_closed(loaded) = ec%open == 0 .and. ec%branch == 0 .and. ec%disagree == 0
      end associate
    end do
  end subroutine closed_pressures

  !> Contact pairs (impactor, target) of the deck: those it lists (a body twice: self-contact),
  !> or every pair of bodies, the impactor chosen by impacts_first ('faces'); with passes = 2
  !> each body pair also the other way round; then each obstacle's bodies against it (target
  !> -k: obstacle k). None when contact is off.
  function contact_pairs(deck, model) result(pairs)
    type(deck_t), intent(in) :: deck
    type(model_t), intent(in) :: model
    integer, allocatable :: pairs(:, :)
    integer :: i, j, p, k, np
    allocate (pairs(2, 0))
    if (.not. deck%contact%enabled) return
    if (deck%contact%npairs > 0) then
      do p = 1, deck%contact%npairs
        call add(body_index(deck%contact%pairs(1, p)), body_index(deck%contact%pairs(2, p)))
      end do
    else
      do i = 1, model%nbody
        do j = i + 1, model%nbody
          if (deck%contact%surface == 'faces' .and. impacts_first(model, j, i)) then
            call add(j, i)
          else
            call add(i, j)
          end if
        end do
      end do
    end if
    if (deck%contact%passes == 2) then
      np = size(pairs, 2)
      do p = 1, np
        if (pairs(1, p) /= pairs(2, p)) call add(pairs(2, p), pairs(1, p))
      end do
    end if
    do k = 1, size(deck%obstacles)
      associate (o => deck%obstacles(k))
        if (o%nbodies == 0) then
          do i = 1, model%nbody
            call add(i, -k)
          end do
        else
          do p = 1, o%nbodies
            call add(body_index(o%bodies(p)), -k)
          end do
        end if
      end associate
    end do
  contains
    subroutine add(a, b)
      integer, intent(in) :: a, b
      integer :: m
      do m = 1, size(pairs, 2)   ! (a pair listed twice is one pair)
        if (pairs(1, m) == a .and. pairs(2, m) == b) return
      end do
      pairs = reshape([pairs, a, b], [2, size(pairs, 2) + 1])
    end subroutine add

    integer function body_index(name)
      character(len=*), intent(in) :: name
      body_index = findloc([(model%body(i)%name == name, i=1, model%nbody)], .true., dim=1)
    end function body_index
  end function contact_pairs

  !> With one pass only the impactor's nodes are tested, so a target's nodes can pass
  !> between them: as the codes advise for a slave surface, the body whose nodes are
  !> clearly denser (area per node `clearly` times smaller) impacts, else the clearly smaller
  !> one (its rim meets the other's face), else the earlier in the deck. Between faces
  !> only: 'mid' contact is one-sided on the target's normal side, which the deck's order
  !> chooses
  logical function impacts_first(model, a, b)
    type(model_t), intent(in) :: model
    integer, intent(in) :: a, b
    real(dp) :: per_node(2)
    per_node = [area_per_node(model, a), area_per_node(model, b)]
    if (per_node(1)*clearly < per_node(2) .or. per_node(2)*clearly < per_node(1)) then
      impacts_first = per_node(1) < per_node(2)
    else
      impacts_first = per_node(1)*nodes_of(model, a)*clearly < per_node(2)*nodes_of(model, b)
    end if
  end function impacts_first

  !> Body b's mid-surface area over its number of nodes [m^2]
  real(dp) function area_per_node(model, b)
    type(model_t), intent(in) :: model
    integer, intent(in) :: b
    integer :: e
    area_per_node = 0
    do e = model%body(b)%elem_first, model%body(b)%elem_last
      area_per_node = area_per_node + element_area(model, e)
    end do
    area_per_node = area_per_node/nodes_of(model, b)
  end function area_per_node

  integer function nodes_of(model, b)
    type(model_t), intent(in) :: model
    integer, intent(in) :: b
    nodes_of = model%body(b)%node_last - model%body(b)%node_first + 1
  end function nodes_of

  !> The contact problem of the deck (contact_pairs), or none: its pairs and obstacles,
  !> tolerance, surfaces and normals, and each pair's coefficients of friction (its
  !> obstacle's, or its own in &contact: the listed pair of the same two bodies, either way
  !> round; else &contact's; static defaults to dynamic). found: it has a pair.
  subroutine scene_contact(deck, model, c, found)
    type(deck_t), intent(in) :: deck
    type(model_t), intent(in) :: model
    type(contact_t), intent(out) :: c
    logical, intent(out) :: found
    integer, allocatable :: pairs(:, :)
    integer :: p, t, j
    real(dp) :: d, st, dc
    allocate (pairs, source=contact_pairs(deck, model))   ! (not on assignment: gfortran warns)
    found = size(pairs, 2) > 0
    if (.not. found) return
    call contact_init(model, pairs, scene_obstacles(deck), deck%contact%tolerance*model%length, &
                      deck%contact%surface == 'faces', c)
    c%opt%nodal_normal = deck%contact%normal == 'nodal'
    if (deck%contact%stiffness /= unset) call contact_set_stiffness(c, model, deck%contact%stiffness)
    do p = 1, c%npairs
      d = deck%contact%friction; st = deck%contact%static_friction; dc = deck%contact%friction_decay
      t = c%pair(2, p)
      if (t < 0) then
        call own(deck%obstacles(-t)%friction, deck%obstacles(-t)%static_friction)
        if (deck%obstacles(-t)%friction_decay /= unset) dc = deck%obstacles(-t)%friction_decay
      else
        do j = 1, deck%contact%npairs
          if (.not. same_bodies(deck%contact%pairs(:, j), c%pair(1, p), t)) cycle
          call own(deck%contact%pair_friction(j), deck%contact%pair_static_friction(j))
          if (deck%contact%pair_friction_decay(j) /= unset) dc = deck%contact%pair_friction_decay(j)
        end do
      end if
      c%mu_d(p) = d
      c%mu_s(p) = merge(st, d, st /= unset)
      if (dc /= unset) c%v_decay(p) = decay_speed(dc)
    end do
  contains
    !> A pair's or obstacle's own coefficients replace &contact's; its own dynamic one alone
    !> is its static one too (&contact's static one could be below it: a plate on a slope
    !> crept by stick-slip where it should have held)
    subroutine own(dyn, sta)
      real(dp), intent(in) :: dyn, sta
      if (dyn /= unset) then
        d = dyn; st = unset
      end if
      if (sta /= unset) st = sta
    end subroutine own

    !> The slip speed v_c over which the sliding coefficient falls by 1/e, 1/DC [m/s]: DC 0
    !> keeps the static coefficient at any speed (huge v_c)
    pure real(dp) function decay_speed(dc)
      real(dp), intent(in) :: dc
      decay_speed = huge(1._dp)
      if (dc > 1/huge(1._dp)) decay_speed = 1/dc   ! (1/dc overflows below that)
    end function decay_speed

    !> the two names are bodies a and b, either way round
    logical function same_bodies(names, a, b)
      character(len=*), intent(in) :: names(2)
      integer, intent(in) :: a, b
      same_bodies = (names(1) == model%body(a)%name .and. names(2) == model%body(b)%name) .or. &
                    (names(2) == model%body(a)%name .and. names(1) == model%body(b)%name)
    end function same_bodies
  end subroutine scene_contact

  !> The deck's rigid obstacles, their normal and axis made unit vectors.
  function scene_obstacles(deck) result(obs)
    type(deck_t), intent(in) :: deck
    type(obstacle_t), allocatable :: obs(:)
    integer :: k
    allocate (obs(size(deck%obstacles)))
    do k = 1, size(obs)
      associate (o => deck%obstacles(k))
        obs(k)%name = o%name; obs(k)%shape = o%shape; obs(k)%point = o%point
        obs(k)%radius = o%radius; obs(k)%inside = o%inside; obs(k)%velocity = o%velocity
        if (o%shape == 'plane') obs(k)%normal = o%normal/norm2(o%normal)
        if (o%shape == 'cylinder') obs(k)%normal = o%axis/norm2(o%axis)
      end associate
    end do
  end function scene_obstacles

  !> Unstressed initial state moving with each body's velocity and spin (about its centroid).
  subroutine initial_state(deck, model, st)
    type(deck_t), intent(in) :: deck
    type(model_t), intent(in) :: model
    type(state_t), intent(out) :: st
    real(dp) :: c(3), w(3)
    integer :: ib, n
    allocate (st%q(model%ndof), st%qd(model%ndof), st%qdd(model%ndof))
    call reference_state(model, st%q)
    st%qd = 0; st%qdd = 0
    do ib = 1, model%nbody
      associate (b => model%body(ib))
        c = sum(model%x0(:, b%node_first:b%node_last), dim=2)/(b%node_last - b%node_first + 1)
        w = deck%bodies(ib)%omega
        do n = b%node_first, b%node_last
          st%qd(dof(n, 1):dof(n, 3)) = deck%bodies(ib)%velocity + cross(w, model%x0(:, n) - c)
          st%qd(dof(n, 4):dof(n, 6)) = cross(w, model%v0(:, n))
        end do
      end associate
    end do
    where (model%fixed) st%qd = 0
  end subroutine initial_state

  !> The node nearest to each tracked point (of the named body, if one is given).
  subroutine tracked_nodes(deck, model, nodes, far)
    type(deck_t), intent(in) :: deck
    type(model_t), intent(in) :: model
    integer, allocatable, intent(out) :: nodes(:)
    !> a warning per track point farther from its node than both 5% of the body's size and
    !> its longest element edge (a point given in the mesh's own coordinates, before the body
    !> was placed, lands silently on whichever node is nearest)
    character(len=300), allocatable, intent(out), optional :: far(:)
    integer :: k, n, kb, e
    real(dp) :: d, best, size_b, edge
    allocate (nodes(deck%output%ntrack))
    if (present(far)) allocate (far(0))
    do k = 1, deck%output%ntrack
      kb = 0
      if (deck%output%track_body(k) /= '') &
        kb = findloc([(model%body(n)%name == deck%output%track_body(k), n=1, model%nbody)], &
                     .true., dim=1)
      best = huge(1._dp); nodes(k) = 1
      do n = 1, model%nnode
        if (kb > 0 .and. model%node_body(n) /= kb) cycle
        d = norm2(model%x0(:, n) - deck%output%track(:, k))
        if (d < best) then
          best = d; nodes(k) = n
        end if
      end do
      if (.not. present(far)) cycle
      associate (b => model%body(model%node_body(nodes(k))))
        size_b = norm2(maxval(model%x0(:, b%node_first:b%node_last), dim=2) - &
                       minval(model%x0(:, b%node_first:b%node_last), dim=2))
        edge = 0
        do e = b%elem_first, b%elem_last
          associate (v => model%x0(:, model%conn(1:3, e)))
            edge = max(edge, norm2(v(:, 1) - v(:, 2)), norm2(v(:, 2) - v(:, 3)), norm2(v(:, 3) - v(:, 1)))
          end associate
        end do
        if (best > max(0.05_dp*size_b, edge)) far = [character(len=300) :: far, '&output track '// &
          itoa(k)//': the nearest node of '''//b%name//''' is '//rtoa(best)//' m from '// &
          vtoa(deck%output%track(:, k))//', '//itoa(nint(100*best/size_b))//'% of the '// &
          'body''s size: track points are in the scene''s coordinates (after center and rotate)']
      end associate
    end do
  end subroutine tracked_nodes

end module casca_scene
