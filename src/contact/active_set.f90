!> The active set: which impactor nodes carry a constraint. Detection adds the nodes that
!> penetrate their target; release drops the constraints whose multiplier turned tensile.
module casca_contact_active_set
  use casca_kinds, only: dp, i8
  use casca_model, only: model_t, dof
  use casca_obstacle, only: obstacle_point
  use casca_contact, only: contact_t, active_set_t, constraint_t, search_radius, face_reach, stick, slip, holds, &
                           new_constraint, around_rim
  use casca_contact_projection, only: positions, body_box, project, constraint_geometry, normal_cache_t, &
                                      normal_cache
  use casca_contact_friction, only: friction_on, beyond_cone, friction_update
  implicit none
  private
  public :: contact_update, contact_release, contact_settle, contact_solve_start, contact_step_start

contains

  !> Refresh the active constraints (normal and gap at their point; with reproject, the point
  !> itself: nearest sub-triangle again) and, with detect, add the penetrating nodes that are
  !> not yet active. Holding the point in late Newton iterations avoids flip-flopping between
  !> two elements at a kink of the C0 surface. Returns the number of constraints added.
  !> touching (per pair): detect its nodes within the tolerance too (gap <= tol, not only
  !> < -tol): the contacts a body rests on at the start
  subroutine contact_update(c, model, q, detect, added, reproject, touching)
    type(contact_t), intent(inout) :: c
    type(model_t), intent(in) :: model
    real(dp), intent(in) :: q(:)
    logical, intent(in) :: detect
    integer, intent(out) :: added
    logical, intent(in), optional :: reproject, touching(:)
    real(dp), allocatable :: x(:, :), q_start(:)
    real(dp) :: boxi(3, 2), boxt(3, 2), r, reach, nrm(3), d, gs
    integer :: ip, bi, bt, n, k
    logical :: found
    type(constraint_t) :: cn
    type(normal_cache_t) :: normals

    added = 0
    allocate (x(3, model%nnode))
    x = positions(model, q)
    c%geo%grid_ok = .false.
    if (c%opt%nodal_normal) call normal_cache(model, normals)
    ! active constraints: project again (the target moves and the node slides), or with
    ! reproject = .false. hold the point
    do k = 1, c%set%nact
      associate (a => c%set%act(k))
        if (a%grip == 0 .and. friction_on(c, a%pair)) a%grip = stick   ! (restart)
        if (c%hold_slip .and. a%grip == slip) a%s = a%s0   ! (friction_hold)
        if (present(reproject) .and. (c%pair(2, a%pair) <= 0 .or. a%elem > 0)) then
          if (.not. reproject) then
            call constraint_geometry(c, model, x, q, a, normals, lever=.true.); cycle
          end if
        end if
        if (c%pair(2, a%pair) > 0) then
          call project(c, model, x, a%node, a%pair, cn, found)
          if (found) then
            a%elem = cn%elem; a%xi = cn%xi; a%sd = cn%sd
            if ((cn%side == around_rim) .neqv. (a%side == around_rim)) then   ! (onto or off a rim)
              a%side = cn%side; a%face(2) = 0
            end if
          else if (a%elem == 0) then   ! restored from a checkpoint, nothing to press on
            a%lambda = 1   ! (released at the next release)
            cycle
          end if   ! (else far from every sub-triangle within reach: keep the last point)
        end if
        call constraint_geometry(c, model, x, q, a, normals, lever=.true.)
        a%bend = in_rounding(a)
      end associate
    end do
    if (.not. detect) return
    do ip = 1, c%npairs
      bi = c%pair(1, ip); bt = c%pair(2, ip)
      boxi = body_box(model, x, bi)
      if (bt <= 0) then   ! an obstacle: every node, by its distance
        reach = search_radius(c, model, bi, bt)
        do n = model%body(bi)%node_first, model%body(bi)%node_last
          call obstacle_point(c%obstacle(-bt), c%time, x(:, n), nrm, d)
          if (d > reach) cycle
          if (holds(c%set, n, ip) .or. all(model%fixed(dof(n, 1):dof(n, 3)))) cycle
          cn = new_constraint(n, ip)
          call take(cn)
        end do
        cycle
      end if
      r = search_radius(c, model, bi, bt)
      boxt = body_box(model, x, bt)
      ! bodies whose boxes (the target's grown by the search radius) are apart cost nothing
      if (any(boxi(:, 1) > boxt(:, 2) + r) .or. any(boxi(:, 2) < boxt(:, 1) - r)) cycle
      ! the sub-triangles are chords of the cubic surface: they find the candidates, the
      ! constraint's own gap decides (else a node released with zero gap would be taken
      ! again at once where the chord lies outside the surface). A cubic arc bulges from
      ! its chord e by kappa e^2 / 8, below a quarter of depth = e / 2 while kappa e < 1
      reach = face_reach(c, model, bi, bt) + 0.25_dp*c%geo%depth(bt)
      do n = model%body(bi)%node_first, model%body(bi)%node_last
        if (any(x(:, n) > boxt(:, 2) + r) .or. any(x(:, n) < boxt(:, 1) - r)) cycle
        if (holds(c%set, n, ip)) cycle
        call project(c, model, x, n, ip, cn, found)
        if (.not. found) cycle
        if (cn%sd >= reach .or. .not. has_free_position(n, cn%elem)) cycle
        if (redundant(cn)) cycle
        call take(cn)
      end do
    end do
    if (added > 0) c%set%changes = c%set%changes + 1
  contains
    !> add cn if its gap is beyond the tolerance (sticking, with friction)
    subroutine take(cn)
      type(constraint_t), intent(inout) :: cn
      real(dp) :: below
      if (friction_on(c, cn%pair)) cn%grip = stick
      call constraint_geometry(c, model, x, q, cn, normals)
      if (c%opt%stick_at_touch .and. cn%grip == stick) then   ! (its slip so far is not stuck)
        cn%u0 = cn%ut
        call constraint_geometry(c, model, x, q, cn, normals)
      end if
      below = -c%opt%tol
      if (present(touching)) then
        if (touching(cn%pair)) below = c%opt%tol
      end if
      if (cn%gap < below) then
        gs = start_gap(cn)
        ! already between the target's faces at the step's start, not held, come in edge-on
        ! (through the rim, past the faces) or sideways: casca has no edge contact, and
        ! pushed out to a face in one step it made energy (a hoop past a plate's corner,
        ! both ways round: 80% of the energy in a step). It is left free.
        if (c%opt%faces .and. gs < -0.25_dp*cn%off) return
        ! inside already: held where it was (between faces; a compliant contact's node is
        ! inside by design, and between mid-surfaces a thin ring's node that came through the
        ! target's one side is taken back, as before: held, one stayed 0.63 mm behind it)
        if (c%opt%faces .and. gs < -c%opt%tol .and. .not. (c%opt%probe .or. c%opt%compliance(cn%node) > 0)) then
          cn%hold = gs; cn%gap = cn%gap - gs   ! (constraint_geometry's gap, less the depth)
          if (.not. cn%gap < -c%opt%tol) return   ! (coming out by itself)
        end if
        ! a node arriving with more slip over the step than Coulomb's impulse can stop,
        ! mu_s times its normal approach in the step (the normal impulse that stops the
        ! approach bounds it), comes in sliding along that slip. Taken sticking it must undo
        ! the step's whole slip, its stick force far outside the cone until the solve turns
        ! it: a thin hoop thrown sliding onto a floor met 900 N against its 1 N weight, a
        ! plate sliding over another's edge 1e3 N against its 3.8 N, and a plate landing on
        ! a stack as it slid dragged the plates under it, and their 172 nodes on the floor,
        ! into slip; the tipping made others tensile, and the sets did not settle. (Until
        ! 2026-11-30 the approach was the depth alone, which a node that closed a gap in the
        ! step exceeds: a rolling hoop's arriving nodes came in sliding, 0.065% of E0 in a
        ! step, so the test was made only in sets that cycled or for nodes released and
        ! taken again, and a three-plate stack ran out of decisions at 25 ms without either.)
        if (cn%grip == stick .and. .not. c%opt%stick_at_touch) then
          if (norm2(cn%ut) > max(c%opt%slip_floor, c%mu_s(cn%pair)*approach(cn, gs))) then
            cn%grip = slip; cn%s = cn%ut/norm2(cn%ut); cn%s0 = cn%s
          end if
        end if
        call constraint_geometry(c, model, x, q, cn, normals, lever=.true.)   ! (its rows' too)
        cn%bend = in_rounding(cn)
        call push(cn)
        added = added + 1
      end if
    end subroutine take

    !> A rim node between faces whose fibre is not along n: its edge may be rounded there
    !> (projection.f90, face: |G.n| below 0.5), where the offset's curvature is Newton's
    !> stiffness (contact_rows' bend row). Decided where a constraint is made or projected
    !> again (a step's first iteration), so that the rows stay the same while the set does.
    logical function in_rounding(a)
      type(constraint_t), intent(in) :: a
      real(dp) :: k
      in_rounding = .false.
      if (.not. (c%opt%faces .and. c%rim(a%node))) return
      k = abs(dot_product(q(dof(a%node, 4):dof(a%node, 6)), a%n))
      in_rounding = k < 0.7_dp
    end function in_rounding

    !> How far cn's node closed on its target along n in the step: its gap at the step's
    !> start (gs, or an obstacle's, where the obstacle was then) less its gap now, and at
    !> least its depth (a node held where it was has that gap already; the start unknown)
    real(dp) function approach(cn, gs)
      type(constraint_t), intent(in) :: cn
      real(dp), intent(in) :: gs
      real(dp) :: nrm(3), d
      integer :: bt
      approach = -cn%gap
      if (cn%hold < 0) return
      bt = c%pair(2, cn%pair)
      if (gs < huge(1._dp)) then
        approach = max(approach, gs - cn%gap)
      else if (bt <= 0 .and. allocated(c%x_start) .and. c%dt > 0) then
        call obstacle_point(c%obstacle(-bt), c%time - c%dt, c%x_start(:, cn%node), nrm, d)
        approach = max(approach, d - (cn%gap + cn%off))   ! (the offset held)
      end if
    end function approach

    !> cn's gap at the step's start (its point, side and faces held), huge where not known
    real(dp) function start_gap(cn)
      type(constraint_t), intent(in) :: cn
      type(constraint_t) :: cs
      integer :: m
      start_gap = huge(1._dp)
      if (cn%elem <= 0 .or. .not. allocated(c%x_start)) return
      if (c%dt <= 0) return
      if (.not. allocated(q_start)) then
        q_start = q
        do m = 1, model%nnode
          q_start(dof(m, 1):dof(m, 3)) = c%x_start(:, m)
          q_start(dof(m, 4):dof(m, 6)) = c%g_start(:, m)
        end do
      end if
      cs = cn
      call constraint_geometry(c, model, c%x_start, q_start, cs)
      start_gap = cs%gap
    end function start_gap

    !> a constraint needs at least one free position on either side
    logical function has_free_position(node, e)
      integer, intent(in) :: node, e
      has_free_position = .not. (all(model%fixed(dof(node, 1):dof(node, 3))) .and. &
                            all(model%fixed(dof(model%conn(:, e), 1))) .and. &
                            all(model%fixed(dof(model%conn(:, e), 2))) .and. &
                            all(model%fixed(dof(model%conn(:, e), 3))))
    end function has_free_position

    !> Two-pass contact: node i pressed on an element of the other body that holds node j,
    !> while j is already pressed on an element that holds i, repeats j's row (the same two
    !> points along the same normal): the saddle point would turn singular, so it is left out
    logical function redundant(cn)
      type(constraint_t), intent(in) :: cn
      integer :: j
      redundant = .false.
      do j = 1, c%set%nact
        associate (o => c%set%act(j))
          if (o%elem == 0) cycle
          if (c%pair(1, o%pair) /= c%pair(2, cn%pair) .or. c%pair(2, o%pair) /= c%pair(1, cn%pair)) cycle
          if (any(model%conn(:, cn%elem) == o%node) .and. any(model%conn(:, o%elem) == cn%node)) then
            redundant = .true.; return
          end if
        end associate
      end do
    end function redundant

    subroutine push(con)
      type(constraint_t), intent(in) :: con
      type(constraint_t), allocatable :: tmp(:)
      if (c%set%nact == size(c%set%act)) then
        allocate (tmp(2*size(c%set%act)))
        tmp(1:c%set%nact) = c%set%act(1:c%set%nact)
        call move_alloc(tmp, c%set%act)
      end if
      c%set%nact = c%set%nact + 1
      c%set%act(c%set%nact) = con
    end subroutine push
  end subroutine contact_update

  !> A new step: a depth held (constraint_t%hold) follows a node that came out part of the
  !> way, up to the surface; it is never pushed out (gap: at the last step's end)
  pure subroutine contact_step_start(c)
    type(contact_t), intent(inout) :: c
    integer :: k
    real(dp) :: g
    do k = 1, c%set%nact
      associate (a => c%set%act(k))
        if (.not. a%hold < 0) cycle
        g = a%gap + a%hold   ! (the gap itself)
        a%hold = min(0._dp, max(a%hold, g))
        a%gap = g - a%hold
      end associate
    end do
  end subroutine contact_step_start

  !> A new solve of a step: no active-set change yet; the sliding directions it starts from
  subroutine contact_solve_start(c)
    type(contact_t), intent(inout) :: c
    integer :: k
    c%set%changes = 0
    c%set%nseen = 0; c%set%cycling = .false.; c%set%decisions = 0
    c%follow_slip = .false.; c%hold_slip = .false.
    c%set%act(1:c%set%nact)%flips = 0
    do k = 1, c%set%nact
      c%set%act(k)%s0 = c%set%act(k)%s
    end do
  end subroutine contact_solve_start

  !> Where Newton has converged for the set: stick/slip changes first, else releases and new
  !> penetrations (which also measures the gaps at q). A trial stick's multiplier may be
  !> tensile only because it stopped the sliding: released first, the node would be taken
  !> again, step after step. changed: how many changes; a release or new contact is one of
  !> the solve's decisions (active_set_t%decisions). With stick = .false. (an iterate near
  !> convergence, not converged) stick and slip are left for later: Coulomb's law has more
  !> than one consistent state, and a hoop rolling from node to node, whose stick or slip was
  !> decided early, made four times the energy in a step.
  subroutine contact_settle(c, model, q, stick, changed)
    type(contact_t), intent(inout) :: c
    type(model_t), intent(in) :: model
    real(dp), intent(in) :: q(:)
    logical, intent(in) :: stick
    integer, intent(out) :: changed
    integer :: released, added, k
    logical :: one_off
    real(dp), allocatable :: s(:, :)   !< the sliding directions of the iterate
    changed = 0
    if (stick) call friction_update(c, changed)
    if (changed > 0) return
    one_off = c%set%cycling   ! (then the tensile go one at a time)
    call contact_release(c, released, keep_stuck=.not. stick)
    s = reshape([(c%set%act(k)%s, k=1, c%set%nact)], [3, c%set%nact])
    call contact_update(c, model, q, .true., added, reproject=.false.)
    changed = released + added
    if (changed == 0) then
      ! a set that settles is converged with the sliding forces its iterate's residual
      ! took: their directions are kept (turned to the slip at q here, a hoop rolling with
      ! friction, whose directions began to follow the slip at the iterate that converged,
      ! had its friction booked up to 90 degrees off the force that moved it, and its
      ! impulse read 0.5% high); the next step turns them (friction_step_done)
      do k = 1, c%set%nact
        c%set%act(k)%s = s(:, k)
      end do
      return
    end if
    ! a cycling set let go one at a time shrinks, and the step's iterations bound it: not
    ! counted (a thin hoop rolling under rho_inf 0.8 went from 7 constraints to its 2 in six
    ! such releases, and ran out of decisions at the last: its step was cut, 18 Newton
    ! iterations a step)
    if (.not. (one_off .and. added == 0)) c%set%decisions = c%set%decisions + 1
    call remember_set(c%set, c%npairs)
  end subroutine contact_settle

  !> Note the set Newton goes on with; one it had already converged for in this solve is a
  !> cycle (a hoop rolling on a floor under friction: three constraints, two of them tensile,
  !> released together; then both penetrating, taken again), broken by releasing one at a
  !> time (contact_release)
  subroutine remember_set(set, npairs)
    type(active_set_t), intent(inout) :: set
    integer, intent(in) :: npairs
    integer(i8) :: key(2)
    key = set_key(set, npairs)
    if (any(set%seen(1, 1:set%nseen) == key(1) .and. set%seen(2, 1:set%nseen) == key(2))) set%cycling = .true.
    if (set%nseen == size(set%seen, 2)) return
    set%nseen = set%nseen + 1
    set%seen(:, set%nseen) = key
  end subroutine remember_set

  !> set_key's number of constraint a
  pure integer(i8) function key_of(a, npairs)
    type(constraint_t), intent(in) :: a
    integer, intent(in) :: npairs
    key_of = int(a%node, i8)*int(npairs + 1, i8) + a%pair
  end function key_of

  !> Two sums over the active constraints, of the (node, pair) numbers and of their squares:
  !> the same for the same set, whatever its order
  pure function set_key(set, npairs) result(key)
    type(active_set_t), intent(in) :: set
    integer, intent(in) :: npairs
    integer(i8) :: key(2), m
    integer :: k
    key = 0
    do k = 1, set%nact
      m = key_of(set%act(k), npairs)
      key = key + [m, m*m]
    end do
  end function set_key

  !> Release the constraints whose multiplier is tensile (lambda > 0); how many were released.
  !> keep_stuck: not a sticking one outside Coulomb's cone (at an iterate that is not
  !> converged, where stick and slip wait): its tension may come from the stick force alone
  !> (a plate landing flat while it spins, every node stuck at first: the stick forces at the
  !> bottom face tilted it, and half its nodes were released, taken again, released...)
  subroutine contact_release(c, released, keep_stuck)
    type(contact_t), intent(inout) :: c
    integer, intent(out) :: released
    logical, intent(in) :: keep_stuck
    integer :: k, m, only
    real(dp) :: most
    only = 0   ! (every tensile one)
    if (c%set%cycling) then   ! only the most tensile
      most = 0
      do k = 1, c%set%nact
        if (tensile(c%set%act(k)) .and. c%set%act(k)%lambda > most) then
          most = c%set%act(k)%lambda; only = k
        end if
      end do
    end if
    m = 0
    do k = 1, c%set%nact
      if (tensile(c%set%act(k)) .and. (only == 0 .or. k == only)) cycle
      m = m + 1
      c%set%act(m) = c%set%act(k)
    end do
    released = c%set%nact - m
    c%set%nact = m
    if (released > 0) c%set%changes = c%set%changes + 1
  contains
    logical function tensile(a)
      type(constraint_t), intent(in) :: a
      tensile = a%lambda > 0 .and. .not. (keep_stuck .and. beyond_cone(c, a))
    end function tensile
  end subroutine contact_release
end module casca_contact_active_set
