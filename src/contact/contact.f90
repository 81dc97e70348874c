!> Non-penetration by Lagrange multipliers (thesis ch. 5): what a contact problem is made of.
!> A pair is (impactor body, target): a body (itself for self-contact) or a rigid obstacle.
!> Every impactor node that penetrates its target gets one multiplier lambda and the condition
!>     g = (x_imp - x_target(xi)) . n(xi) - offset = 0,   x_target = N_j(xi) Y^j,
!> linearised with xi, n and the offset held (eq. 5.6); between faces the row also holds the
!> gap's derivative through n's turn (projection.f90, normal_lever), since the faces' points
!> are off the normal through the target point. lambda < 0 is compression (the force
!> on the impactor is -lambda n); a multiplier that turns tensile at convergence is released.
!> The jobs live in their own files: projection.f90 (the point, normal and gap of one
!> constraint), active_set.f90 (detection and release), rows.f90 (C, forces), correction.f90
!> (the velocity after a step), probes.f90 (diagnostics).
module casca_contact
  use casca_kinds, only: dp, i8
  use casca_model, only: model_t
  use casca_shape_tri10, only: tri10_shape, tri10_node_xi
  use casca_surface_search, only: surface_t, grid_t, surface_init
  use casca_obstacle, only: obstacle_t
  implicit none
  private
  public :: contact_t, contact_options_t, active_set_t, constraint_t, target_geometry_t
  public :: contact_init, face_reach, search_radius
  public :: contact_set_stiffness, normal_compliance, normal_residual, holds, tested_both_ways
  public :: new_constraint, slip_followed, set_restore

  !> Most nodes a target normal depends on (the elements around its element's 10 nodes:
  !> about 70 on a mesh of valence 6); a constraint with more leaves its lever out
  integer, parameter, public :: max_lever = 100

  integer, parameter, public :: around_rim = 2   !< constraint_t%side of a node at a rim

  type :: constraint_t
    integer :: node = 0, pair = 0
    integer :: elem = 0         !< target element; 0: an obstacle, or not projected yet (restart)
    !> side of a two-sided target the node is on (+-1), 0: not known; around_rim: beside an
    !> open surface's rim, whose edge the node meets (projection.f90, rim_normal)
    integer :: side = 0
    real(dp) :: xi(2) = 0, n(3) = 0, shp(10) = 0
    !> where the force acts on the target (projection.f90, force_point): its face's point on
    !> the node's line along n at the configuration the internal force is taken at; the rows
    !> of C keep xi and shp, which define the gap
    real(dp) :: xif(2) = 0, shpf(10) = 0
    !> the normal the force acts along: n, but for a curved obstacle its normal at the node's
    !> face point at that configuration (contact_force_points), so that a frictionless force
    !> has no moment about the obstacle's axis or centre there
    real(dp) :: nf(3) = 0
    real(dp) :: gap = 0, lambda = 0
    real(dp) :: g0 = 0          !< the gap at the step's start (0 for a constraint made in it)
    !> <= 0: the depth a node was already at when the step that took it began (left out as
    !> repeating the other pass's row, or come between nodes): the gap is held there, not
    !> pushed out in one step, which made energy (a ball glancing off a thin plate with
    !> passes = 2: 18% of E0 in a step); it shrinks as the node comes out (contact_step_start)
    real(dp) :: hold = 0
    real(dp) :: off = 0         !< faces' offset (0 between mid-surfaces)
    !> the gap's derivative on the fibres: wg(1) n.dG at the node, wg(2) sum_j N_j n.dG_j
    real(dp) :: wg(2) = 0
    !> the gap's second derivative on the impactor node's fibre, -wgg n n^T: nonzero where a
    !> rim node's edge is rounded (projection.f90, face); with -lambda it is Newton's stiffness
    !> along n on that fibre (contact_rows' bend row)
    real(dp) :: wgg = 0
    logical :: bend = .false.   !< with a bend row in Newton's system (contact_update decides)
    !> between faces, the gap's derivative through the target normal's turn, D . dn/dx_a
    !> (projection.f90, normal_lever) on the positions of the nodes lnode(1:nl) that n
    !> depends on: lgrad for the gap's row, lgradf (with wgf, the fibres' weights) for the
    !> force's, taken where the scheme takes the internal force
    !> (allocated to nl by set_lever: held inline at max_lever they made a constraint 5.6 kB,
    !> and a plate's 961 contacts on a floor, which have none, spent a tenth of the run
    !> copying them with the active set)
    integer :: nl = 0
    integer, allocatable :: lnode(:)
    real(dp), allocatable :: lgrad(:, :), lgradf(:, :)
    real(dp) :: wgf(2) = 0
    !> which face (+-1 on the fibre) of the impactor node and of the target is in
    !> contact, chosen when the constraint is made (0: not yet)
    integer :: face(2) = 0
    real(dp) :: sd = 0          !< signed distance to the sub-triangles when last projected
    real(dp) :: mu = 0          !< the acceleration's correction: M a += C^T mu (after a step)
    ! Coulomb friction
    integer :: grip = 0         !< 0 frictionless, stick or slip
    real(dp) :: t(3, 2) = 0     !< tangents across n (the stick rows' directions)
    real(dp) :: lt(2) = 0       !< stick multipliers: the force on the node is -lt(1) t1 - lt(2) t2
    real(dp) :: mut(2) = 0      !< their acceleration correction
    real(dp) :: gt(2) = 0       !< stick rows' gaps: relative tangential displacement in the step
    !> slip direction of the node relative to the target: its slip over the step at the last
    !> iterate (friction_geometry), held while that slip is below slip_floor
    real(dp) :: s(3) = 0
    real(dp) :: s0(3) = 0       !< s at the solve's start (a slip that turns against it stopped)
    !> a sliding constraint's force across s, along n x s, from Newton's last increment (its
    !> multiplier on the row across the slip, contact_rows): the turn of the sliding force
    !> that s takes at the next iterate, and where the iterate is the last, part of the force
    !> that acted (friction_force)
    real(dp) :: lturn = 0
    real(dp) :: ut(3) = 0       !< relative tangential displacement in the step
    real(dp) :: u0(3) = 0       !< (stick_at_touch) its part before the contact was made
    !> the friction force on the node at the step's start (the last step's end), for its work
    real(dp) :: fa(3) = 0
    integer :: flips = 0        !< stick/slip changes in this step
  end type constraint_t

  integer, parameter, public :: stick = 1, slip = 2
  real(dp), parameter :: slip_share = 1e-8_dp   !< slip_floor over the scene size

  !> The target bodies' surfaces as the search and the normals need them.
  type :: target_geometry_t
    type(surface_t), allocatable :: surf(:)     !< per body (only targets are built)
    real(dp), allocatable :: depth(:)           !< per body: half the mean sub-triangle edge
    real(dp), allocatable :: skip(:)            !< per body: self-contact ignores its surface
                                                !< within this reference distance of the node
    type(grid_t), allocatable :: grid(:)        !< per pair: the target near the impactor
    logical, allocatable :: grid_ok(:)          !< grid of this pair rebuilt for this q
    ! the target elements at node n: node_elem(node_start(n) : node_start(n+1) - 1), and which
    ! of their nodes n is (node_loc); shape derivatives at the 10 nodes (dphi_node)
    integer, allocatable :: node_start(:), node_elem(:), node_loc(:)
    real(dp) :: dphi_node(10, 2, 10) = 0
  end type target_geometry_t

  !> How contact is modelled: fixed for the run by the deck and the time scheme.
  type :: contact_options_t
    real(dp) :: tol = 0                         !< penetration accepted [m]
    logical :: nodal_normal = .true.            !< n from nodal normals, else the element's
    logical :: faces = .true.                   !< contact at the shell faces, else mid-surfaces
    !> per node: its normal constraint's compliance, penetration per unit force [m/N]
    !> (contact_set_stiffness); 0 everywhere: hard contact, no penetration (the thesis)
    real(dp), allocatable :: compliance(:)
    logical :: compliant = .false.              !< some compliance is not 0
    real(dp) :: alpha_f = 0                     !< the time scheme's: where a compliant force is taken
    !> a slip over the step shorter than this [m] does not turn s: its direction is Newton's
    !> round-off (tol = 1e-10 of the scene size), and the sliding force's stiffness across it,
    !> mu_d |lambda| / |ut|, would turn the rows hard (a trial without this floor met slips of
    !> 1e-19 m at slip onset, and singular Schur complements)
    real(dp) :: slip_floor = 0
    !> statics: a contact made in a load increment sticks where it touched, not where its node
    !> was at the increment's start (a cantilever's tip slides a long way before it touches)
    logical :: stick_at_touch = .false.
    !> a probe (probes.f90): measures penetrations, holds none
    logical :: probe = .false.
  end type contact_options_t

  !> The constraints holding now, and what the solve has learnt of them (active_set.f90).
  type :: active_set_t
    integer :: nact = 0
    type(constraint_t), allocatable :: act(:)
    integer :: changes = 0                      !< active-set changes in this step
    !> the releases and new contacts decided in this solve (contact_settle), which Newton
    !> bounds; stick/slip turns alone are not among them (friction_update turns a node at
    !> most three times in a solve: counted, a plate at rest on an incline under rho_inf 0.8,
    !> its nodes slipping and sticking again a batch at a time, ran out of decisions)
    integer :: decisions = 0
    !> the sets this solve has settled into (active_set.f90's set_key), and whether it came
    !> back to one of them: then tensile constraints go one at a time
    integer(i8) :: seen(2, 16) = 0
    integer :: nseen = 0
    logical :: cycling = .false.
  end type active_set_t

  !> A contact problem: its options, pairs and obstacles, the targets' geometry, the active
  !> set, the step's start that friction measures slip from, and the accounts per pair.
  type :: contact_t
    type(contact_options_t) :: opt
    ! the problem
    integer :: npairs = 0
    integer, allocatable :: pair(:, :)          !< (2, npairs) impactor body, target: a body,
                                                !< or -k for obstacle k
    type(obstacle_t), allocatable :: obstacle(:)
    real(dp) :: time = 0                        !< obstacles are where they are at this time
    !> per node: on its shell's free edge (the rim), the only place a node can touch edge-on
    logical, allocatable :: rim(:)
    real(dp), allocatable :: mu_d(:), mu_s(:)   !< Coulomb friction per pair: dynamic, static
    !> per pair: the slip speed over which the sliding coefficient falls from mu_s towards
    !> mu_d by 1/e, 1/DC of friction_decay [m/s] (rows.f90, sliding_coefficient); 0: at once
    real(dp), allocatable :: v_decay(:)
    type(target_geometry_t) :: geo
    type(active_set_t) :: set
    ! the step: its start positions and fibres and its length (friction needs them: without
    ! them contact is frictionless)
    real(dp), allocatable :: x_start(:, :), g_start(:, :)
    real(dp) :: dt = 0
    !> sliding directions follow the slip at this iterate (Newton sets it once an iterate is
    !> near); else each holds its last. hold_slip: not in this solve (friction_hold)
    logical :: follow_slip = .false., hold_slip = .false.
    ! accounts
    real(dp), allocatable :: friction_work(:)   !< per pair: dissipated by sliding so far [J]
    !> per pair: the kinetic energy the velocity corrections took out so far (hard contact) [J]
    real(dp), allocatable :: correction_loss(:)
    real(dp) :: obstacle_work = 0               !< done on the bodies by moving obstacles [J]
    ! per pair: the impulse on the impactor so far, as the integrator applied it, and the
    ! contact's share of M a at the start of the next step [N s, N]
    real(dp), allocatable :: impulse(:, :), carry(:, :)
  end type contact_t

contains

  !> A constraint of node on pair p, not yet projected (its lever's arrays are not set)
  pure function new_constraint(node, p) result(con)
    integer, intent(in) :: node, p
    type(constraint_t) :: con
    con%node = node; con%pair = p
  end function new_constraint

  !> pairs(2, npairs): impactor and target of each pair (-k: obstacle k of obstacles).
  !> tol: accepted penetration [m]; faces: contact at the shell faces.
  subroutine contact_init(model, pairs, obstacles, tol, faces, c)
    type(model_t), intent(in) :: model
    integer, intent(in) :: pairs(:, :)
    type(obstacle_t), intent(in) :: obstacles(:)
    real(dp), intent(in) :: tol
    logical, intent(in) :: faces
    type(contact_t), intent(out) :: c
    integer :: b, e, k, n
    real(dp) :: edge, phi(10), diam
    logical, allocatable :: target_elem(:)
    type(surface_t) :: own
    c%npairs = size(pairs, 2)
    c%pair = pairs
    allocate (c%opt%compliance(model%nnode))
    c%opt%compliance = 0
    c%obstacle = obstacles
    c%opt%tol = tol
    c%opt%faces = faces
    allocate (c%rim(model%nnode))
    c%rim = .false.
    do b = 1, model%nbody
      if (.not. any(pairs(1, :) == b)) cycle
      associate (bd => model%body(b))
        call surface_init(model%conn, [(e, e=bd%elem_first, bd%elem_last)], own)
        do k = 1, own%ntri
          where (own%rim_vertex(:, k)) c%rim(own%tri(:, k)) = .true.
        end do
      end associate
    end do
    allocate (c%set%act(16), c%mu_d(c%npairs), c%mu_s(c%npairs), c%v_decay(c%npairs), &
              c%friction_work(c%npairs), c%correction_loss(c%npairs))
    c%mu_d = 0; c%mu_s = 0; c%v_decay = 0; c%friction_work = 0; c%correction_loss = 0
    c%opt%slip_floor = slip_share*model%length
    allocate (c%impulse(3, c%npairs), c%carry(3, c%npairs))
    c%impulse = 0; c%carry = 0
    associate (g => c%geo)
      allocate (g%surf(model%nbody), g%grid(c%npairs), g%grid_ok(c%npairs), g%depth(model%nbody), &
                g%skip(model%nbody))
      g%grid_ok = .false.; g%depth = 0; g%skip = 0
      do b = 1, model%nbody
        if (.not. any(pairs(2, :) == b)) cycle
        associate (bd => model%body(b))
          call surface_init(model%conn, [(e, e=bd%elem_first, bd%elem_last)], g%surf(b))
          ! half the mean sub-triangle edge: a node deeper than that is behind the surface,
          ! not through it (matters at the rim of open surfaces)
          edge = 0
          do k = 1, g%surf(b)%ntri
            edge = edge + norm2(model%x0(:, g%surf(b)%tri(1, k)) - model%x0(:, g%surf(b)%tri(2, k)))
          end do
          g%depth(b) = 0.5_dp*edge/g%surf(b)%ntri
          ! self-contact: the elements at the node (within the largest element's size) and
          ! the surface the search could reach from the node's own place are never targets
          diam = 0
          do e = bd%elem_first, bd%elem_last
            do k = 1, 3
              diam = max(diam, norm2(model%x0(:, model%conn(k, e)) - model%x0(:, model%conn(mod(k, 3) + 1, e))))
            end do
          end do
          g%skip(b) = max(1.01_dp*diam, 1.5_dp*search_radius(c, model, b, b))
        end associate
      end do
      ! the elements of the targets at each node (counted, then filled)
      allocate (target_elem(model%nelem), g%node_start(model%nnode + 1))
      target_elem = .false.
      do b = 1, model%nbody
        if (any(pairs(2, :) == b)) target_elem(model%body(b)%elem_first:model%body(b)%elem_last) = .true.
      end do
      g%node_start = 0
      do e = 1, model%nelem
        if (target_elem(e)) g%node_start(model%conn(:, e) + 1) = g%node_start(model%conn(:, e) + 1) + 1
      end do
      g%node_start(1) = 1
      do n = 1, model%nnode
        g%node_start(n + 1) = g%node_start(n + 1) + g%node_start(n)
      end do
      allocate (g%node_elem(g%node_start(model%nnode + 1) - 1), g%node_loc(g%node_start(model%nnode + 1) - 1))
      do e = 1, model%nelem
        if (.not. target_elem(e)) cycle
        do k = 1, 10
          n = model%conn(k, e)
          g%node_elem(g%node_start(n)) = e; g%node_loc(g%node_start(n)) = k
          g%node_start(n) = g%node_start(n) + 1
        end do
      end do
      g%node_start(2:) = g%node_start(1:model%nnode); g%node_start(1) = 1
      do k = 1, 10
        call tri10_shape(tri10_node_xi(1, k), tri10_node_xi(2, k), phi, g%dphi_node(:, :, k))
      end do
    end associate
  end subroutine contact_init

  !> A compliant contact (penalty, as Abaqus/Standard's and the explicit codes'): an active
  !> constraint's pressure grows with its penetration at stiffness [Pa/m], so node n's
  !> force is stiffness A_n times its penetration, A_n the area it carries (its row of the
  !> element mass's position block over density times thickness: the integral of its shape
  !> function). The constraint row becomes g - lambda / (stiffness A_n) = 0 (a perturbed
  !> Lagrangian): the force is a continuous function of the gap, so a node comes into
  !> contact over a time the steps can resolve rather than stopping within one step.
  subroutine contact_set_stiffness(c, model, stiffness)
    type(contact_t), intent(inout) :: c
    type(model_t), intent(in) :: model
    real(dp), intent(in) :: stiffness
    real(dp), allocatable :: area(:)
    integer :: e, k
    allocate (area(model%nnode))
    area = 0
    do e = 1, model%nelem
      associate (b => model%body(model%elem_body(e)))
        do k = 1, 10
          area(model%conn(k, e)) = area(model%conn(k, e)) + &
                                   sum(model%emass(k, 1:10, e))/(b%density*b%thickness)
        end do
      end associate
    end do
    c%opt%compliance = 1/(stiffness*max(area, tiny(1._dp)))
    c%opt%compliant = .true.
  end subroutine contact_set_stiffness

  !> Whether sliding constraint a's direction s follows its slip ut at this iterate: the slip
  !> is past the slip floor and still along s0, the way it went at the solve's start (a slip
  !> that turns against it stopped, and sticks at convergence, friction_update: following
  !> it, s would turn round with it and Newton cycle, as a block stopping on a floor did)
  pure logical function slip_followed(c, a)
    type(contact_t), intent(in) :: c
    type(constraint_t), intent(in) :: a
    slip_followed = .false.
    if (c%follow_slip .and. a%grip == slip) &
      slip_followed = norm2(a%ut) >= c%opt%slip_floor .and. norm2(a%ut) > 0 .and. dot_product(a%ut, a%s0) > 0
  end function slip_followed

  !> The active set back to the constraints act it held (kept when a solve or a step began)
  pure subroutine set_restore(set, act)
    type(active_set_t), intent(inout) :: set
    type(constraint_t), intent(in) :: act(:)
    set%nact = size(act)
    set%act(1:size(act)) = act
  end subroutine set_restore

  !> Whether the active set holds a constraint of node on pair p
  pure logical function holds(set, node, p)
    type(active_set_t), intent(in) :: set
    integer, intent(in) :: node, p
    holds = any(set%act(1:set%nact)%node == node .and. set%act(1:set%nact)%pair == p)
  end function holds

  !> The compliance of constraint a's normal row as the row carries it [m/N] (0: hard). The
  !> time scheme takes forces at its alpha level, so a compliant force is lambda =
  !> k ((1 - alpha_f) g + alpha_f g0) (g0: the gap at the step's start); the row is that over
  !> k (1 - alpha_f): g + alpha_f / (1 - alpha_f) g0 - lambda / (k (1 - alpha_f)) = 0
  !> (taken at the step's end, as a hard row is, the force lags: a plate dropped flat on a
  !> compliant floor came back at 0.87 of its speed under rho_inf 0.8 at 40 us, and the error
  !> halved with the step, first order)
  pure real(dp) function normal_compliance(c, a)
    type(contact_t), intent(in) :: c
    type(constraint_t), intent(in) :: a
    normal_compliance = c%opt%compliance(a%node)/(1 - c%opt%alpha_f)
  end function normal_compliance

  !> The residual of constraint a's normal row (its gap, for a hard contact)
  pure real(dp) function normal_residual(c, a)
    type(contact_t), intent(in) :: c
    type(constraint_t), intent(in) :: a
    normal_residual = a%gap
    if (c%opt%compliance(a%node) > 0) normal_residual = a%gap + c%opt%alpha_f/(1 - c%opt%alpha_f)*a%g0 - &
                                                    normal_compliance(c, a)*a%lambda
  end function normal_residual

  !> How far apart the mid-surfaces of impactor bi and target bt (a body, or <= 0: an
  !> obstacle) can be when their faces touch: half of each thickness, with room for the
  !> fibres' stretch (0 between mid-surfaces)
  pure real(dp) function face_reach(c, model, bi, bt)
    type(contact_t), intent(in) :: c
    type(model_t), intent(in) :: model
    integer, intent(in) :: bi, bt
    face_reach = 0
    if (.not. c%opt%faces) return
    face_reach = 0.5_dp*model%body(bi)%thickness
    if (bt > 0) face_reach = face_reach + 0.5_dp*model%body(bt)%thickness
    face_reach = 1.25_dp*face_reach
  end function face_reach

  !> Whether bodies bi and bt are tested both ways round: (bi, bt) and (bt, bi) are pairs
  pure logical function tested_both_ways(c, bi, bt)
    type(contact_t), intent(in) :: c
    integer, intent(in) :: bi, bt
    tested_both_ways = any(c%pair(1, :) == bi .and. c%pair(2, :) == bt) .and. &
                       any(c%pair(1, :) == bt .and. c%pair(2, :) == bi)
  end function tested_both_ways

  !> How far from the target's mid-surface a node of bi is looked for: the faces' reach and,
  !> for a body, the band below its surface; for an obstacle, the contact tolerance
  pure real(dp) function search_radius(c, model, bi, bt)
    type(contact_t), intent(in) :: c
    type(model_t), intent(in) :: model
    integer, intent(in) :: bi, bt
    if (bt > 0) then
      search_radius = face_reach(c, model, bi, bt) + c%geo%depth(bt)
    else
      search_radius = face_reach(c, model, bi, bt) + max(c%opt%tol, 0._dp)   ! (a probe's -huge: any gap)
    end if
  end function search_radius
end module casca_contact
