!> What `casca check` says about a built scene before it runs (LS-DYNA's and OpenRadioss'
!> starter, Abaqus' datacheck): per body its size, mass, smallest element, element quality and
!> the step its elements suggest; the time step against them; the equations' size; and
!> warnings that leave the deck runnable: normals pointing into a closed body, distorted
!> elements, pairs that never meet, steps a node can cross the contact band in.
!>
!> Every figure comes from the model as built (reference positions, element data, mass):
!>   mass      the sum of the consistent mass's Y-Y entries of one component (rho times the
!>             element volume, its thickness integrated through the reference fibres)
!>   area      the cubic mid-surface, 7-point rule
!>   l_min     the shortest edge between an element's vertex nodes
!>   quality   the element's min/max of the area Jacobian dX/dxi1 x dX/dxi2 (along its
!>             centroid's normal) over the 7 points: 1 for straight-sided elements with
!>             evenly spaced edge nodes, falls as edge or centre nodes move off their places,
!>             below 0 where the element folds over (aspect ratio does not lower it)
!>   c         sqrt(E / (rho (1 - nu^2))), the membrane (plate) wave speed: membrane waves
!>             up to ~ 2 c / l_min, an element estimate
!>   thickness the fibre's stretch through the thickness, ~ 2 sqrt(3) c_d / h (c_d =
!>             sqrt((lambda + 2 mu) / rho)): stiffness (lambda + 2 mu) h against the fibre's
!>             inertia rho h^3 / 12 per area. The highest frequency of a shell mesh unless its
!>             elements are smaller than the thickness (a free plate's highest is 1.08 to 1.12
!>             times it: tests/test_starter_freq.f90)
!>   step      explicit stable step ~ 2 / omega_max of the two; estimates, not eigenvalues
module casca_starter
  use casca_kinds, only: dp, pi
  use casca_mesh, only: nen
  use casca_deck, only: deck_t, unset, frame_interval
  use casca_model, only: model_t, body_t, dof, element_dofs, area_points, element_area
  use casca_shape_tri10, only: tri10_shape, tri10_normal
  use casca_orientation, only: edge_census_t, edge_census, signed_volume, shortest_edge
  use casca_strings, only: itoa, rtoa, vtoa, ftoa, count_of
  use casca_scene, only: scene_contact, initial_state, tracked_nodes, area_per_node, clearly
  use casca_newmark, only: state_t
  use casca_contact, only: contact_t, search_radius, tested_both_ways
  use casca_pair_gaps, only: pair_gap_t, pair_gaps_at
  use casca_sanity, only: bytes_per_element
  implicit none
  private
  public :: body_facts_t, body_facts, starter_report, thickness_frequency, put_warnings, contact_time, spring_time
  public :: deck_warnings

  !> Below this element quality a warning names the element: the area scale of its map then
  !> varies by more than a factor 2 over it
  real(dp), parameter :: min_quality = 0.5_dp
  !> Steps per period a vibration needs to be followed by the implicit step
  real(dp), parameter :: steps_per_period = 10

  !> One body's figures
  type :: body_facts_t
    integer :: nodes = 0, elements = 0
    real(dp) :: mass = 0, area = 0          !< [kg], [m^2]
    real(dp) :: lo(3) = 0, hi(3) = 0        !< bounding box [m]
    real(dp) :: l_min = 0                   !< shortest vertex-to-vertex edge [m]
    real(dp) :: quality = 1                 !< worst element quality ...
    integer :: worst = 0                    !< ... and its element (within the body)
    integer :: distorted = 0                !< elements below min_quality
    real(dp) :: c = 0                       !< membrane wave speed [m/s]
    real(dp) :: omega_m = 0, omega_t = 0    !< membrane and thickness estimates [rad/s]
    type(edge_census_t) :: edges            !< orientation and closure of its mesh
    logical :: closed = .false.             !< every edge of two elements
    real(dp) :: volume = 0                  !< enclosed, signed by the normals (closed meshes)
  end type body_facts_t

contains

  !> Body b's figures
  pure function body_facts(model, b) result(f)
    type(model_t), intent(in) :: model
    integer, intent(in) :: b
    type(body_facts_t) :: f
    integer :: e
    real(dp) :: q
    associate (bd => model%body(b), &
               x => model%x0(:, model%body(b)%node_first:model%body(b)%node_last))
      f%nodes = bd%node_last - bd%node_first + 1
      f%elements = bd%elem_last - bd%elem_first + 1
      f%mass = bd%mass
      f%lo = minval(x, dim=2); f%hi = maxval(x, dim=2)
      f%l_min = huge(1._dp)
      f%quality = huge(1._dp)
      do e = bd%elem_first, bd%elem_last
        f%area = f%area + element_area(model, e)
        f%l_min = min(f%l_min, shortest_edge(model%x0(:, model%conn(1:3, e))))
        q = element_quality(model, e)
        if (q < min_quality) f%distorted = f%distorted + 1
        if (q < f%quality) then
          f%quality = q; f%worst = e - bd%elem_first + 1
        end if
      end do
      f%c = sqrt(bd%young/(bd%density*(1 - bd%poisson**2)))
      f%omega_m = 2*f%c/f%l_min
      f%omega_t = thickness_frequency(bd%lam, bd%mu, bd%density, bd%thickness)
      associate (conn => model%conn(:, bd%elem_first:bd%elem_last) - bd%node_first + 1)
        f%edges = edge_census(conn, f%nodes)
        f%closed = f%edges%open == 0 .and. f%edges%branch == 0
        if (f%closed) f%volume = signed_volume(x, conn)
      end associate
    end associate
  end function body_facts

  !> The fibre's stretch mode through the thickness h of a shell of Lame constants lam, mu
  !> and density rho: sqrt(k / m) with k = (lam + 2 mu) h and m = rho h^3 / 12 per area
  pure real(dp) function thickness_frequency(lam, mu, rho, h) result(omega)
    real(dp), intent(in) :: lam, mu, rho, h
    omega = 2*sqrt(3*(lam + 2*mu)/rho)/h
  end function thickness_frequency

  !> Element e's min/max of the area Jacobian over the model's area points, signed by the
  !> element's normal at its centroid: below 0 the map folds over inside the element
  pure real(dp) function element_quality(model, e) result(q)
    type(model_t), intent(in) :: model
    integer, intent(in) :: e
    real(dp) :: j(area_points), phi(nen), dphi(nen, 2), nc(3)
    integer :: ia
    call tri10_shape(1._dp/3, 1._dp/3, phi, dphi)
    nc = tri10_normal(model%x0(:, model%conn(:, e)), dphi)
    do ia = 1, area_points
      j(ia) = dot_product(tri10_normal(model%x0(:, model%conn(:, e)), model%rule%dphi(:, :, ia)), &
                          nc)
    end do
    q = minval(j)/maxval(j)
  end function element_quality

  !> The starter's report of a built scene: the facts to unit out, the warnings to unit err
  subroutine starter_report(deck, model, out, err)
    type(deck_t), intent(in) :: deck
    type(model_t), intent(in) :: model
    integer, intent(in) :: out, err
    type(body_facts_t) :: f(model%nbody)
    integer :: b
    integer, allocatable :: tracked(:)
    character(len=300), allocatable :: far(:)
    do b = 1, model%nbody
      f(b) = body_facts(model, b)
    end do
    write (out, '(a)') 'bodies (mass from the consistent mass matrix; l_min: shortest edge '// &
      'between vertex nodes; quality: min/max of the area Jacobian over an element''s 7 '// &
      'points, worst element, < 0 folded; c = sqrt(E/(rho (1 - nu^2))), the membrane wave '// &
      'speed; c_d = sqrt((lambda + 2 mu)/rho); frequencies and steps are estimates):'
    do b = 1, model%nbody
      call body_lines(model, b, f(b), out)
    end do
    write (out, '(a)') 'scene size '//rtoa(model%length)//' m: the diagonal of the box around '// &
      'every node at the start, the length that &run tolerance (without tolerance_length), '// &
      'newton_tol and &contact tolerance are relative to'
    if (deck%run%analysis == 'dynamic') call step_line(deck, model, f, out)
    call memory_line(model, out)
    if (deck%run%analysis == 'dynamic') call time_line(deck, model, out)
    call put_warnings(body_warnings(model, f), err)
    call put_warnings(pair_warnings(deck, model), err)
    call put_warnings(deck_warnings(deck), err)
    call tracked_nodes(deck, model, tracked, far)
    call put_warnings(far, err)
  end subroutine starter_report

  !> What the deck's settings mean that it may not intend: frames between the fixed steps'
  !> ends; in statics, the obstacles' motion left out (they stay where they are at t = 0) and
  !> bodies that no restraint holds
  function deck_warnings(deck) result(w)
    type(deck_t), intent(in) :: deck
    character(len=400), allocatable :: w(:)
    real(dp) :: interval, steps
    integer :: k
    allocate (w(0))
    if (deck%run%analysis /= 'static') then
      ! (a clamped strip under an end moment from t = 0 diverged in its second step, at 62
      ! steps a period; with rho_inf 0.8 or dt / 2 it ran)
      if (any([(any(deck%loads(k)%moment /= 0), k=1, size(deck%loads))]) .and. deck%run%rho_inf == unset &
          .and. deck%run%gamma > 0.5_dp) w = [character(len=400) :: w, '&load moment from t = 0: the '// &
        'fibres start at the acceleration of their small rotary inertia, M^-1 m, which the thesis'' '// &
        'Newmark (beta, gamma) carries into their velocities; if the first steps fail, rho_inf = 0.8 '// &
        '(generalized-alpha) damps it, or take a shorter dt']
      ! (a frame is written at the first step's end at or past its time; with a tolerance the
      ! steps are the interval halved and end on it)
      interval = frame_interval(deck)
      steps = interval/deck%run%dt
      if (deck%run%tolerance == unset .and. abs(steps - anint(steps)) > 1e-6_dp*steps) &
        w = [character(len=400) :: w, '&output interval '//rtoa(interval)//' s is '//ftoa(steps)// &
             ' steps of dt: each frame is written at the end of the first step past its time, up to '// &
             'dt late (run.pvd gives each its own time); an interval of a whole number of steps '// &
             'puts them on time']
      return
    end if
    do k = 1, size(deck%obstacles)
      if (any(deck%obstacles(k)%velocity /= 0)) w = [character(len=400) :: w, 'obstacle '''// &
        trim(deck%obstacles(k)%name)//''' has a velocity, but in statics the obstacles stay '// &
        'where they are at t = 0']
    end do
    do k = 1, size(deck%bodies)   ! (a run stops at the first load step: no equilibrium)
      if (any(deck%restraints(:)%body == deck%bodies(k)%name)) cycle
      if (deck%run%linear) then
        w = [character(len=400) :: w, 'body '''//trim(deck%bodies(k)%name)//''' has no '// &
          '&restraint: a linear analysis solves K0 u = f, singular for a body free to move: '// &
          'restrain its rigid motion (loads that balance each other: 3-2-1, at three nodes)']
        cycle
      end if
      w = [character(len=400) :: w, 'body '''//trim(deck%bodies(k)%name)//''' has no '// &
        '&restraint: in statics only contacts can hold it against the loads, and if none '// &
        'does from the first load step there is no equilibrium to find (loads that balance '// &
        'each other, a pressure on a closed surface, have one: restraining its rigid motion '// &
        'at three nodes, 3-2-1, finds it directly, not by the damped path)']
    end do
  end function deck_warnings

  !> The warning lines w, each 'warning: ...', to unit u
  subroutine put_warnings(w, u)
    character(len=*), intent(in) :: w(:)
    integer, intent(in) :: u
    integer :: k
    do k = 1, size(w)
      write (u, '(a)') 'warning: '//trim(w(k))
    end do
  end subroutine put_warnings

  !> Body b's lines of the report
  subroutine body_lines(model, b, f, u)
    type(model_t), intent(in) :: model
    integer, intent(in) :: b, u
    type(body_facts_t), intent(in) :: f
    character(len=24) :: mass
    character(len=:), allocatable :: shape
    write (mass, '(es19.12)') f%mass
    if (f%closed) then
      shape = 'closed, enclosing '//rtoa(abs(f%volume))//' m^3, normals '// &
              trim(merge('outwards', 'inwards ', f%volume > 0))
    else
      shape = 'open ('//count_of(f%edges%open, 'boundary edge', 'boundary edges')
      if (f%edges%branch > 0) shape = shape//', '//count_of(f%edges%branch, 'edge', 'edges')// &
                                      ' of three or more elements'
      shape = shape//')'
    end if
    associate (bd => model%body(b))
      write (u, '(a)') '  body '''//bd%name//''': '//count_of(f%nodes, 'node', 'nodes')//', '// &
        count_of(f%elements, 'element', 'elements')//', thickness '//rtoa(bd%thickness)// &
        ' m, area '//rtoa(f%area)//' m^2, mass '//trim(adjustl(mass))//' kg'
      write (u, '(a)') '    box '//vtoa(f%lo)//' to '//vtoa(f%hi)//' m, size '// &
        rtoa(f%hi(1) - f%lo(1))//' x '//rtoa(f%hi(2) - f%lo(2))//' x '//rtoa(f%hi(3) - f%lo(3))// &
        ' m; mesh '//shape
      write (u, '(a)') '    l_min '//rtoa(f%l_min)//' m, quality '//rtoa(f%quality)// &
        ' (element '//itoa(f%worst)//'); c '//rtoa(f%c)//' m/s: membrane waves up to ~ 2 c / '// &
        'l_min = '//rtoa(f%omega_m)//' rad/s; the fibre''s stretch through the thickness ~ '// &
        '2 sqrt(3) c_d / h = '//rtoa(f%omega_t)//' rad/s; explicit stable step ~ '// &
        '2 / omega_max = '//rtoa(2/max(f%omega_m, f%omega_t))//' s'
    end associate
  end subroutine body_lines

  !> The deck's dt against the membrane waves of the finest mesh, and what it follows
  subroutine step_line(deck, model, f, u)
    type(deck_t), intent(in) :: deck
    type(model_t), intent(in) :: model
    type(body_facts_t), intent(in) :: f(:)
    integer, intent(in) :: u
    real(dp) :: dt, tc
    integer :: b
    dt = deck%run%dt
    b = maxloc(f%omega_m, dim=1)
    write (u, '(a)') 'time step: dt '//rtoa(dt)//' s: membrane waves cross dt c / l_min = '// &
      rtoa(dt*f(b)%c/f(b)%l_min)//' smallest elements per step (body '''//model%body(b)%name// &
      '''); at '//itoa(nint(steps_per_period))//' steps per period dt follows vibrations up to '// &
      rtoa(1/(steps_per_period*dt))//' Hz, membrane waves go up to ~ '// &
      rtoa(f(b)%omega_m/(2*pi))//' Hz, the thickness stretch to ~ '// &
      rtoa(maxval(f%omega_t)/(2*pi))//' Hz (the implicit step stays stable; '// &
      damping()//')'
    if (deck%contact%stiffness == unset) return
    tc = contact_time(deck, model, b)
    write (u, '(a)') 'contact: stiffness '//rtoa(deck%contact%stiffness)//' Pa/m: a shell of this scene '// &
      'on a rigid surface stays in contact about pi sqrt(rho h / stiffness) = '// &
      rtoa(tc)//' s (body '''//model%body(b)%name//'''), '// &
      rtoa(tc/dt)//' steps of dt (a plate''s bounce lost 1% of its '// &
      'energy over 16 steps of it, 3e-5 over 31: docs/method.md)'
  contains
    !> what the deck's scheme does with what the step does not follow
    function damping() result(s)
      character(len=:), allocatable :: s
      if (deck%run%rho_inf /= unset) then
        s = 'generalized-alpha damps what it does not follow, to rho_inf = '//rtoa(deck%run%rho_inf)// &
            ' at the highest frequencies'
      else if (deck%run%gamma > 0.5_dp) then
        s = 'Newmark with gamma > 1/2 damps what it does not follow'
      else
        s = 'Newmark with gamma = 1/2 keeps what it does not follow, undamped'
        ! (an untuned scene: a ring spinning into another, 18% high in impulse at dt 1e-5 s,
        ! still 11% at 2.5e-6 s, where generalized-alpha and Newmark gamma > 1/2 agreed to 1%)
        if (deck%contact%enabled .and. deck%contact%stiffness == unset) s = s//'; with hard '// &
          'contact every node''s impact rings on undamped and the impulses converge slowly with '// &
          'dt: rho_inf = 0.8 (generalized-alpha) damps that ringing, second order'
      end if
    end function damping
  end subroutine step_line

  !> A compliant contact's time for its stiffest body, pi sqrt(rho h / stiffness) (a flat shell
  !> of density rho and thickness h on a rigid surface: half a period of the mass on its
  !> springs); b: that body. huge without a stiffness.
  real(dp) function contact_time(deck, model, b)
    type(deck_t), intent(in) :: deck
    type(model_t), intent(in) :: model
    integer, intent(out) :: b
    integer :: k
    real(dp) :: t
    contact_time = huge(1._dp); b = 1
    if (deck%contact%stiffness == unset) return
    do k = 1, model%nbody
      t = spring_time(model%body(k), deck%contact%stiffness)
      if (t < contact_time) then
        contact_time = t; b = k
      end if
    end do
  end function contact_time

  !> How long a shell of body bd stays on a rigid surface of this compliance: half the period
  !> of its mass per area rho h on the spring per area, pi sqrt(rho h / stiffness)
  pure real(dp) function spring_time(bd, stiffness)
    type(body_t), intent(in) :: bd
    real(dp), intent(in) :: stiffness
    spring_time = pi*sqrt(bd%density*bd%thickness/stiffness)
  end function spring_time

  !> The equations' size: unknowns, the matrix entries the elements hand to the solver (each
  !> element's lower triangle of free pairs, assembly.f90), and the memory sanity.f90 budgets
  subroutine memory_line(model, u)
    type(model_t), intent(in) :: model
    integer, intent(in) :: u
    real(dp) :: entries
    integer :: e, nf
    entries = 0
    do e = 1, model%nelem
      nf = count(.not. model%fixed(element_dofs(model, e)))
      entries = entries + 0.5_dp*real(nf, dp)*(nf + 1)
    end do
    write (u, '(a)') 'equations: '//count_of(count(.not. model%fixed), 'unknown', 'unknowns')// &
      ', '//rtoa(entries)//' matrix entries from the elements; memory ~ '// &
      rtoa(model%nelem*bytes_per_element/1e6_dp)//' MB with the factors (40 kB per element: '// &
      '36 kB measured on a sphere of 11,520 elements, with a margin; docs/performance.md)'
  end subroutine memory_line

  !> A rough run time on one rank: steps x (Newton iterations x (c_call + c_elem x elements)
  !> + factorisations x c_fact x the sum over the bodies of n^1.5, n a body's unknowns), on
  !> what the deck says of its steps and contacts (docs/performance.md, "casca check's run
  !> time"). The former figure, the steps at dt times 0.03 to 0.08 ms per element, held for
  !> impacts (thesis rings and spheres) and was 5 to 180 times low where contacts work every
  !> step: a hoop rolling with friction (5 Newton iterations a step, a new factorisation every
  !> other one), a ball rolling in a bowl under tolerance (769 steps for t_end / dt = 100, a
  !> factorisation nearly every step: 172 s for 1 to 2.6).
  subroutine time_line(deck, model, u)
    type(deck_t), intent(in) :: deck
    type(model_t), intent(in) :: model
    integer, intent(in) :: u
    !> a Newton iteration: s, and s per element (3.0 to 20.5 ms of CPU measured on 80 to 320
    !> elements: two rings, a hoop rolling, a ball on a compliant floor, a ball in a bowl); a
    !> factorisation: s per n^1.5 (0.13 to 0.15 s for a sphere's 10,094 unknowns, 17 ms for a
    !> hoop's 3,360)
    real(dp), parameter :: c_call = 2e-3_dp, c_elem = 20e-6_dp, c_fact = 1.3e-7_dp
    character(len=:), allocatable :: busy, steps_why, fact_why
    integer :: newton, b
    real(dp) :: steps, facts, n15, hi, lo, iter, total
    busy = busy_contact(deck, model)
    ! the steps: with tolerance chosen as the run goes, on the grid of the frame interval
    ! halved; while contacts work, between the longest at most dt (after a contact begins)
    ! and the shortest, dt / 2^max_step_cuts: their geometric mean
    steps = deck%run%t_end/deck%run%dt
    steps_why = 'steps (t_end / dt)'
    if (deck%run%tolerance /= unset) then
      steps_why = 'steps (t_end / dt; tolerance chooses them as the run goes, longer while no '// &
                  'contact works)'
      if (busy /= '') then
        hi = frame_interval(deck)
        do while (hi > deck%run%dt)
          hi = hi/2
        end do
        lo = hi
        do while (lo > deck%run%dt/2**deck%run%max_step_cuts)
          lo = lo/2
        end do
        steps = deck%run%t_end/sqrt(hi*lo)
        steps_why = 'steps of '//rtoa(sqrt(hi*lo))//' s (tolerance chooses them; while contacts '// &
                    'work they lie between '//rtoa(lo)//' and '//rtoa(hi)//' s: assumed at their '// &
                    'geometric mean)'
      end if
    end if
    newton = merge(5, 2, busy /= '')
    if (deck%run%tolerance /= unset) then
      facts = 1; fact_why = 'every step (its length changes)'
    else if (index(busy, 'friction') > 0) then
      facts = 0.5_dp; fact_why = 'every other step (stick and slip turn)'
    else
      facts = 0.01_dp; fact_why = 'every 100th step (the factors kept)'
    end if
    n15 = 0
    do b = 1, model%nbody
      associate (bd => model%body(b))
        n15 = n15 + real(count(.not. model%fixed(dof(bd%node_first, 1):dof(bd%node_last, 7))), dp)**1.5_dp
      end associate
    end do
    iter = c_call + c_elem*model%nelem
    total = steps*(newton*iter + facts*c_fact*n15)
    if (busy == '') busy = 'no contact working every step'
    write (u, '(a)') 'run time: ~ '//rtoa(total)//' s on one idle core, within about 2x where '// &
      'these hold: '//rtoa(steps)//' '//steps_why//'; '//itoa(newton)//' Newton iterations a '// &
      'step ('//busy//'; 5 where friction, a compliant contact or a body lying on its contact '// &
      'works every step, else 2) at '//rtoa(iter)//' s ('//rtoa(c_call)//' s + '//rtoa(c_elem)// &
      ' s x '//count_of(model%nelem, 'element', 'elements')//'); a factorisation '//fact_why// &
      ' at '//rtoa(c_fact*n15)//' s ('//rtoa(c_fact)//' s x n^1.5 for n unknowns a body); '// &
      'contacts by the hundred '// &
      '(a crush) cost more, bodies idle in free flight less'
  end subroutine time_line

  !> Why the deck's contacts work every step, '' if they need not: friction, a compliant
  !> contact (its depth changes in every step), or a body lying on its contact (within the
  !> band a step detects) under gravity or a load
  function busy_contact(deck, model) result(why)
    type(deck_t), intent(in) :: deck
    type(model_t), intent(in) :: model
    character(len=:), allocatable :: why
    type(contact_t) :: c
    type(state_t) :: st
    type(pair_gap_t), allocatable :: pg(:)
    integer :: p, bi, bt
    logical :: found, pressed
    why = ''
    call scene_contact(deck, model, c, found)
    if (.not. found) return
    if (any(c%mu_s > 0) .or. any(c%mu_d > 0)) then
      why = 'friction'
    else if (deck%contact%stiffness /= unset) then
      why = 'a compliant contact'
    else
      call initial_state(deck, model, st)
      pg = pair_gaps_at(c, model, st%q, st%qd)
      do p = 1, c%npairs
        bi = c%pair(1, p); bt = c%pair(2, p)
        if (bi == bt .or. pg(p)%gap > search_radius(c, model, bi, bt)) cycle
        pressed = driven(model, bi)
        if (bt > 0) pressed = pressed .or. driven(model, bt)
        if (pressed) then
          why = 'a body lying on its contact'; return
        end if
      end do
    end if
  end function busy_contact

  !> Whether gravity or a load acts on body b
  logical function driven(model, b)
    type(model_t), intent(in) :: model
    integer, intent(in) :: b
    associate (bd => model%body(b))
      driven = any(bd%gravity /= 0) .or. any(model%fext(dof(bd%node_first, 1):dof(bd%node_last, 7)) /= 0)
    end associate
  end function driven

  !> Normals into a closed body, distorted elements, edges of three elements or more
  function body_warnings(model, f) result(w)
    type(model_t), intent(in) :: model
    type(body_facts_t), intent(in) :: f(:)
    character(len=400), allocatable :: w(:)
    integer :: b
    allocate (w(0))
    do b = 1, size(f)
      associate (name => model%body(b)%name)
        if (f(b)%closed .and. f(b)%volume < 0) call add(w, &
          'body '''//name//''': its mesh is closed and its normals point inwards (the volume '// &
          'its orientation encloses is '//rtoa(f(b)%volume)//' m^3); contact between '// &
          'mid-surfaces meets it on its inner side only; &body flip_normals = .true. reverses them')
        if (f(b)%distorted > 0) call add(w, 'body '''//name//''': '// &
          count_of(f(b)%distorted, 'element is', 'elements are')//' distorted (quality below '// &
          rtoa(min_quality)//': the area Jacobian varies by more than a factor 2 over the '// &
          'element, below 0 it folds over); the worst, element '//itoa(f(b)%worst)//', has '// &
          rtoa(f(b)%quality))
        if (f(b)%edges%branch > 0) call add(w, 'body '''//name//''': '// &
          count_of(f(b)%edges%branch, 'edge is', 'edges are')//' shared by three or more '// &
          'elements (a T-junction of shells, or a stray element); the shells there share one '// &
          'fibre, averaged from all their normals, which is normal to none of them: mesh the '// &
          'parts that meet there as separate bodies, or remove the stray elements')
      end associate
    end do
  end function body_warnings

  !> Pairs that never meet at the initial velocities while nothing else can set them moving
  !> (gravity, a load, a closing pair, or a body these push), pairs whose closing speed
  !> carries a node across the target's contact band (search_radius: what a step can still
  !> detect) in one step, and pairs between faces tested one way only whose target's nodes
  !> are clearly denser than the impactor's. Dynamic runs only (statics has no speeds).
  function pair_warnings(deck, model) result(w)
    type(deck_t), intent(in) :: deck
    type(model_t), intent(in) :: model
    character(len=400), allocatable :: w(:)
    type(contact_t) :: c
    type(state_t) :: st
    type(pair_gap_t), allocatable :: pg(:)
    character(len=:), allocatable :: label
    logical :: pushed(model%nbody)   ! by gravity, a load or a closing pair
    real(dp) :: band, ratio
    integer :: p, bi, bt
    logical :: found
    allocate (w(0))
    if (deck%run%analysis /= 'dynamic') return
    call scene_contact(deck, model, c, found)
    if (.not. found) return
    call initial_state(deck, model, st)
    pg = pair_gaps_at(c, model, st%q, st%qd)
    do bi = 1, model%nbody
      pushed(bi) = driven(model, bi)
    end do
    do p = 1, c%npairs
      if (pg(p)%time < 0 .or. c%pair(1, p) == c%pair(2, p)) cycle
      pushed(c%pair(1, p)) = .true.
      if (c%pair(2, p) > 0) pushed(c%pair(2, p)) = .true.
    end do
    ! a pushed body pushes what it can touch (a row of balls, the first one thrown), until
    ! nothing more is set moving
    do
      found = .false.
      do p = 1, c%npairs
        bi = c%pair(1, p); bt = c%pair(2, p)
        if (bt <= 0 .or. bi == bt) cycle
        if (pushed(bi) .neqv. pushed(bt)) then
          pushed(bi) = .true.; pushed(bt) = .true.; found = .true.
        end if
      end do
      if (.not. found) exit
    end do
    do p = 1, c%npairs
      bi = c%pair(1, p); bt = c%pair(2, p)
      if (bi == bt .or. pg(p)%node == 0) cycle   ! (self-contact: rigid motion closes nothing)
      if (bt > 0) then
        label = 'pair '''//model%body(bi)%name//''' -> '''//model%body(bt)%name//''''
      else
        label = 'pair '''//model%body(bi)%name//''' -> '''//trim(c%obstacle(-bt)%name)//''''
      end if
      if (pg(p)%time < 0) then
        if (pushed(bi)) cycle
        if (bt > 0) then
          if (pushed(bt)) cycle
        end if
        call add(w, label//' never meets: its closing speed is '//rtoa(pg(p)%speed)// &
                 ' m/s, and no gravity, load or other pair sets either side moving')
      else if (bt > 0) then
        band = search_radius(c, model, bi, bt)
        if (pg(p)%speed*deck%run%dt > band) call add(w, label// &
          ' closes '//rtoa(pg(p)%speed*deck%run%dt)//' m in one step (closing speed '// &
          rtoa(pg(p)%speed)//' m/s), more than the '//rtoa(band)//' m band in which contact '// &
          'finds a node: a node can cross the target unseen; dt below '// &
          rtoa(band/pg(p)%speed)//' s keeps it in')
      end if
      ! (only the impactor's nodes are held off the other surface)
      if (bt > 0 .and. deck%contact%surface == 'faces' .and. .not. tested_both_ways(c, bi, bt)) then
        ! (a blade dropped edge-first between a finer plate's node rows passed through it with
        ! no contact, exit 0)
        if (pg(p)%rim .and. sqrt(area_per_node(model, bi)) > model%body(bt)%thickness) &
          call add(w, label//': the contact foreseen first is at the target''s free edge, met '// &
                   'edge-on, and only the impactor''s nodes are held off it: an edge thinner ('// &
                   rtoa(model%body(bt)%thickness)//' m) than the impactor''s node spacing (about '// &
                   rtoa(sqrt(area_per_node(model, bi)))//' m) can pass between them, through '// &
                   'the impactor unseen; passes = 2 holds the edge''s own nodes off its face')
        ratio = area_per_node(model, bi)/area_per_node(model, bt)
        if (ratio > clearly) &
          call add(w, label//': the target''s nodes are '//rtoa(ratio)//' times denser '// &
                   '(area per node) than the impactor''s, and only the impactor''s are held off '// &
                   'the other surface: the target''s may pass between them; list the pair '// &
                   'the other way round, or passes = 2')
      end if
    end do
  end function pair_warnings

  !> Append text to the list w
  pure subroutine add(w, text)
    character(len=*), allocatable, intent(inout) :: w(:)
    character(len=*), intent(in) :: text
    w = [character(len=len(w)) :: w, text]
  end subroutine add
end module casca_starter
