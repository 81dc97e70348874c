!> What a run watches as it goes and warns of where it ends or stops: the energy a step
!> made, the least stretches through the thickness and along the faces, the deepest a node
!> sank, Coulomb's bound
module casca_run_watch
  use casca_kinds, only: dp
  use casca_deck, only: deck_t
  use casca_starter, only: contact_time
  use casca_model, only: thinnest, least_face_stretch
  use casca_accounting, only: energy_term_t, balance_remainder, energy_put
  use casca_contact, only: contact_t
  use casca_contact_rows, only: pair_stored_energy, contact_newton_nrows
  use casca_mpi, only: is_root
  use casca_strings, only: count_of, rtoa, vtoa, ftoa, itoa
  use casca_run_state, only: run_t, least_t, svk_limit
  implicit none
  private
  public :: watch_energy, watch_stability, watch_thickness, watch_faces, watch_sink, squeezed, squeeze_note, rest_now, &
            made_judged, warn_at_end, balance_terms, moving_obstacles

  !> energy a step made within this many steps after a contact's release is put down to it
  integer, parameter :: released_steps = 4

contains

  !> Keep the largest energy one step made: E0 less what the bodies hold and the terms
  !> taken out (energy_balance's remainder) is what the integrator and the contact removed,
  !> and it may only grow with a dissipative scheme (stay, with a conservative one)
  subroutine watch_energy(r, rest, start, h_before)
    type(run_t), intent(inout) :: r
    real(dp), intent(in) :: rest   !< the balance's remainder now (rest_now)
    type(contact_t), intent(in), optional :: start   !< the contact at the step's start
    real(dp), intent(in), optional :: h_before   !< the step before's length if it was free, else 0
    real(dp) :: made
    made = made_judged(r, r%rest_last - rest)
    if (made > r%made_max) then
      r%made_max = made; r%t_made = r%st%t; r%dt_made = r%nm%dt; r%touch_made = r%t_touch
      r%dt_made_before = 0
      if (present(h_before) .and. r%sc%tol <= 0) then   ! (fixed steps, grown back after cuts)
        if (h_before > 0 .and. r%nm%dt > 1.5_dp*h_before) r%dt_made_before = h_before
      end if
      r%made_contacts = 0; r%made_between = 0   ! (those of a step that released them acted in it too)
      if (allocated(r%contact)) call count_active(r%contact)
      if (present(start)) call count_active(start)
    end if
    r%rest_last = rest
    r%e_scale = max(r%e_scale, abs(r%bal%total), r%bal%kinetic + r%bal%strain, abs(r%bal%work))
    if (allocated(r%contact)) then
      if (r%contact%set%nact > 0) r%t_touch = r%st%t
    end if
  contains
    subroutine count_active(c)
      type(contact_t), intent(in) :: c
      r%made_contacts = max(r%made_contacts, c%set%nact)
      r%made_between = max(r%made_between, count(c%pair(2, c%set%act(1:c%set%nact)%pair) > 0))
    end subroutine count_active
  end subroutine watch_energy

  !> Statics: keep where the load step just taken (rep, at load factor r%st%t) had negative
  !> pivots in its tangent stiffness. The saddle-point matrix has one negative pivot per
  !> contact row besides the stiffness's own on what the rows leave free (its inertia, as
  !> the Schur path counts it too). Counted from a load step that had none on, or from the
  !> unloaded state where its own factorisation had none (static_run, unloaded_inertia: a
  !> column past Euler's load in its first step): a body that its contacts alone hold, or
  !> nothing (a free sphere under pressure), has zero pivots of round-off's sign from its
  !> start, and a stabilised step's tangent is such a one.
  subroutine watch_stability(r, stabilised)
    type(run_t), intent(inout) :: r
    logical, intent(in) :: stabilised   !< the step took the stabilised path
    integer :: neg
    if (stabilised) return
    neg = r%rep%neg_pivots
    if (allocated(r%contact)) neg = neg - contact_newton_nrows(r%contact)
    if (neg <= 0 .and. r%stability%t_first < 0) r%stability%t_before = r%st%t
    if (neg <= 0 .or. r%stability%t_before < 0) return
    if (r%stability%t_first < 0) r%stability%t_first = r%st%t
    r%stability%t_last = r%st%t
    r%stability%most = max(r%stability%most, neg)
  end subroutine watch_stability

  !> A static path that went through load steps whose tangent stiffness is not positive
  !> definite says so: past a bifurcation or a limit load the equilibria load control
  !> follows are unstable (Sze's strip rolled by an end moment, from about 280 degrees on:
  !> it twists out of its plane; a run of small load steps cannot get past that point,
  !> docs/performance.md)
  subroutine warn_unstable(r)
    type(run_t), intent(in) :: r
    character(len=:), allocatable :: upto
    if (r%stability%t_first < 0) return
    upto = ' on'
    if (r%stability%t_last < r%st%t) upto = ' to '//rtoa(r%stability%t_last)
    write (0, '(a)') 'warning: the tangent stiffness had negative pivots from load factor '// &
      rtoa(r%stability%t_first)//upto//' (at most '//itoa(r%stability%most)//'; none at '// &
      rtoa(r%stability%t_before)//'): the load passed a buckling point, a bifurcation or a limit '// &
      'load, between '//rtoa(r%stability%t_before)//' and '//rtoa(r%stability%t_first)//', and '// &
      'the equilibria load control found past it are unstable ones, which the structure would '// &
      'leave (analysis = ''dynamic'' follows where it goes)'
  end subroutine warn_unstable

  !> Keep the least thickness stretch of the run's states (thinnest; every step)
  subroutine watch_thickness(r)
    type(run_t), intent(inout) :: r
    real(dp) :: stretch
    integer :: node
    call thinnest(r%model, r%st%q, node, stretch)
    call keep_least(r%thick, stretch, node, r%st%t)
  end subroutine watch_thickness

  !> Keep the least stretch along the faces (least_face_stretch): at the frames' times and where
  !> the run ends or stops, as it costs about 0.6 us an element, 1.5% of a step of the three
  !> spheres
  subroutine watch_faces(r)
    type(run_t), intent(inout) :: r
    real(dp) :: stretch
    integer :: node
    if (.not. (allocated(r%model%face_metric) .and. allocated(r%st%q))) return   ! (stopped before)
    call least_face_stretch(r%model, r%st%q, node, stretch)
    call keep_least(r%face, stretch, node, r%st%t)
  end subroutine watch_faces

  !> Keep the deepest a contact node sank into its target (the history row's penetration,
  !> depth, at its node): warn_sink tells of it
  pure subroutine watch_sink(r, depth, node)
    type(run_t), intent(inout) :: r
    real(dp), intent(in) :: depth
    integer, intent(in) :: node
    if (depth <= r%sink) return
    r%sink = depth; r%sink_node = node; r%t_sink = r%st%t
  end subroutine watch_sink

  pure subroutine keep_least(least, stretch, node, t)
    type(least_t), intent(inout) :: least
    real(dp), intent(in) :: stretch, t
    integer, intent(in) :: node
    if (stretch < svk_limit .and. least%t_past < 0) least%t_past = t
    if (stretch < least%stretch) least = least_t(stretch, t, node, least%t_past)
  end subroutine keep_least

  !> A shell squeezed past Saint-Venant-Kirchhoff's limit (svk_limit), through its thickness
  !> or along a face: squeezed further its stress falls, so the equations lose their solution
  !> there (a rubber ring thrown at a floor at 15 m/s reached 0.2 through its thickness, a
  !> ring crushed flat folded to 0.4 along its inner face; Newton stalled)
  logical function squeezed(r)
    type(run_t), intent(in) :: r
    squeezed = min(r%thick%stretch, r%face%stretch) < svk_limit
  end function squeezed

  function squeeze_note(r) result(msg)
    type(run_t), intent(in) :: r
    character(len=:), allocatable :: msg
    msg = ''
    if (r%thick%stretch < svk_limit) then
      if (r%thick%stretch <= 0) then
        msg = at(r%thick, 'turned inside out through its thickness')
      else
        msg = at(r%thick, 'squeezed through its thickness to '//itoa(nint(100*r%thick%stretch))//'%')
      end if
    end if
    if (r%face%stretch < svk_limit) then
      if (len(msg) > 0) msg = msg//', and '
      msg = msg//at(r%face, 'compressed along its face to '//itoa(nint(100*r%face%stretch))// &
            '% (folded or bent tighter than its thickness allows)')
    end if
    msg = msg//'; the Saint-Venant-Kirchhoff material holds to '//itoa(nint(100*svk_limit))// &
          '% only (squeezed further, its stress falls): the results there are beyond the material law'
    if (r%thick%stretch < svk_limit) msg = msg//' (a slower impact, or a thicker or stiffer shell, stays within it)'
  contains
    function at(least, how) result(s)
      type(least_t), intent(in) :: least
      character(len=*), intent(in) :: how
      character(len=:), allocatable :: s
      integer :: b
      b = r%model%node_body(least%node)
      s = 'body '''//r%model%body(b)%name//''' was '//how//' at its node '// &
          itoa(least%node - r%model%body(b)%node_first + 1)//' (at '// &
          vtoa(r%model%x0(:, least%node))//' at the start) at t = '//rtoa(least%t)//' s'
      if (least%t_past < least%t) s = s//' (below '//itoa(nint(100*svk_limit))//'% from t = '// &
                                      rtoa(least%t_past)//' s)'
    end function at
  end function squeeze_note


  !> energy_balance's remainder at the run's state: E0 less what the bodies hold and the
  !> terms taken out (what the integrator and the contact removed so far)
  real(dp) function rest_now(r)
    type(run_t), intent(in) :: r
    rest_now = balance_remainder(r%bal0, r%bal, balance_terms(r%deck, r%contact))
  end function rest_now

  !> The energy the step just taken made, as it is judged: on the first step of a start held
  !> by its contacts (held_at_start) less m g^2 dt^2, at least what that start makes by itself
  !> (that step went unjudged, and a hoop thrown spinning along a rough floor it lay on made
  !> 17.6% of E0 there in silence)
  pure real(dp) function made_judged(r, made)
    type(run_t), intent(in) :: r
    real(dp), intent(in) :: made
    made_judged = made
    if (r%held_at_start .and. r%st%step == 1) made_judged = made - r%held_g2*r%nm%dt**2
  end function made_judged

  !> What a run warns of at its end or stop (rank 0): a node sunk into its target; in
  !> statics an unstable path; in dynamics energy made and Coulomb's bound
  subroutine warn_at_end(r)
    type(run_t), intent(in) :: r
    if (.not. is_root()) return
    call warn_sink(r)
    if (r%deck%run%analysis == 'static') then
      call warn_unstable(r); return
    end if
    call warn_energy(r)
    call warn_made_total(r)
    call warn_coulomb(r)
  end subroutine warn_at_end

  !> The energy the run made over all its steps, not one step's doing: where the printed
  !> balance's remainder ends below -1% of the energy put in and below twice the most one
  !> step made (warn_energy's), said (a hoop
  !> thrown spinning along a rough floor under a tolerance ended 1.5% above E0 in silence)
  subroutine warn_made_total(r)
    type(run_t), intent(in) :: r
    real(dp) :: rest, put
    character(len=:), allocatable :: what
    type(energy_term_t), allocatable :: terms(:)
    if (r%restart_step >= 0) return
    terms = balance_terms(r%deck, r%contact, corrections=.true.)
    rest = balance_remainder(r%bal0, r%bal, terms)
    call energy_put(r%bal0, r%bal, terms, put, what, held=r%e_scale)
    if (.not. (-rest > 1e-2_dp*put .and. -rest > 2*r%made_max)) return   ! (not one step's doing)
    write (0, '(a)') 'warning: over the run the time integrator and contact made '// &
      ftoa(-100*rest/put)//'% of '//what//' (the energy balance''s remainder, below 0), no step '// &
      'much of it alone: forces out of step with the motion they work on, as friction at a '// &
      'slipping contact; take a shorter dt or a smaller tolerance, and compare'
  end subroutine warn_made_total

  !> Hard contact holds each node within its tolerance, but a node left free of a constraint
  !> that would repeat one held the other way (two passes, self-contact) may sink: where it
  !> sank more than a tenth of its shell's thickness, say so (two thin spheres glancing at
  !> 50 m/s with passes = 2: 30% of h, in silence)
  subroutine warn_sink(r)
    type(run_t), intent(in) :: r
    character(len=:), allocatable :: at
    integer :: b
    if (.not. allocated(r%contact) .or. r%sink_node == 0) return
    if (r%contact%opt%compliant) return   ! (a spring's depth is its force over its stiffness)
    b = r%model%node_body(r%sink_node)
    if (r%sink <= 0.1_dp*r%model%body(b)%thickness) return
    at = 'at t = '//rtoa(r%t_sink)//' s'
    if (r%deck%run%analysis == 'static') at = 'at load factor '//rtoa(r%t_sink)
    write (0, '(a)') 'warning: a contact node of body '''//trim(r%model%body(b)%name)//''' sank '// &
      rtoa(r%sink)//' m ('//itoa(nint(100*r%sink/r%model%body(b)%thickness))//'% of its thickness) '// &
      'into its target '//at//' (its node '// &
      itoa(r%sink_node - r%model%body(b)%node_first + 1)//'; the penetration column of history.dat): '// &
      'a node pressed on an element that holds a node pressed back is left free of the constraint '// &
      'that would repeat the other''s, may sink, and is held where it is found (passes = 2, '// &
      'self-contact; README, &contact passes); with passes = 1 (the denser mesh as impactor) or a '// &
      'compliant contact (stiffness) no constraint is left out'
  end subroutine warn_sink

  !> Coulomb's bound over the run, where it can be read from the impulse column: a pair with a
  !> plane obstacle (one normal) takes at most mu times its normal impulse along the plane. The
  !> trapezoidal rule's contact forces ring, and the friction of a hoop hopping on a floor came
  !> to 0.56 of its normal impulse at mu 0.3 (the acceleration's projection moves the normal
  !> share of the step's start, not the friction's: docs/performance.md)
  subroutine warn_coulomb(r)
    type(run_t), intent(in) :: r
    real(dp) :: jn, jt, mu
    integer :: p
    if (.not. allocated(r%contact)) return
    associate (c => r%contact)
      do p = 1, c%npairs
        if (c%pair(2, p) >= 0) cycle
        if (c%obstacle(-c%pair(2, p))%shape /= 'plane') cycle
        mu = max(c%mu_d(p), c%mu_s(p))
        if (mu <= 0) cycle
        jn = dot_product(c%impulse(:, p), c%obstacle(-c%pair(2, p))%normal)
        jt = norm2(c%impulse(:, p) - jn*c%obstacle(-c%pair(2, p))%normal)
        if (jn <= 0 .or. jt <= 1.02_dp*mu*jn) cycle
        write (0, '(a)') 'warning: pair '''//trim(r%model%body(c%pair(1, p))%name)//''' -> '''// &
          trim(c%obstacle(-c%pair(2, p))%name)//''': its friction impulse is '//ftoa(jt/jn)// &
          ' of its normal impulse, above its coefficient '//ftoa(mu)//' (Coulomb''s bound): '// &
          'the contact forces rang from step to step'//trim(ringing())
      end do
    end associate
  contains
    function ringing() result(s)
      character(len=:), allocatable :: s
      s = '; a shorter dt brings it nearer'
      if (r%nm%gamma <= 0.5_dp .and. r%nm%rho_inf < 0) s = ' ('//r%nm%describe()//' keeps them '// &
        'undamped: rho_inf = 0.8 (generalized-alpha) damps them)'
    end function ringing
  end subroutine warn_coulomb

  !> A run from t = 0 whose step made more than 1e-3 of E0 says so: with contact active most
  !> often the contact's doing; with none, the time scheme's, over a motion its steps do not
  !> follow (the schemes keep or remove the energy of linear vibrations, not of every
  !> nonlinear one)
  subroutine warn_energy(r)
    type(run_t), intent(in) :: r
    character(len=:), allocatable :: made, why, shorter
    real(dp) :: e0, tc
    integer :: b
    e0 = abs(r%bal0%total)
    if (r%restart_step >= 0 .or. .not. r%made_max > 1e-3_dp*max(e0, r%e_scale)) return
    if (e0 >= 1e-3_dp*r%e_scale) then
      made = ftoa(100*r%made_max/e0)//'% of the initial energy'
    else   ! (a scene that starts at rest under its loads)
      made = rtoa(r%made_max)//' J (the bodies held at most '//rtoa(r%e_scale)//' J)'
    end if
    why = 'a node that came deep into a target in one step'
    if (allocated(r%contact) .and. r%made_between > 0) then   ! (closed shells have no rim)
      if (any(r%contact%rim)) why = 'a shell''s edge that passed between the other''s nodes (casca has '// &
                                    'no edge-to-edge contact; with one pass, test the edge''s body as impactor or '// &
                                    'set passes = 2), or a node that came deep into a target in one step'
    end if
    ! (under a tolerance the steps in contact are the error estimate's, which leaves the
    ! contact nodes out: two balls head-on made 0.24% in a 100 us step at 1e-3)
    shorter = 'a shorter dt'
    if (r%sc%tol > 0) shorter = 'a smaller tolerance'
    why = why//'; look at the frames there, or take '//shorter
    ! (an 80-degree plate landing edge-first under the trapezoidal rule: 0.72% of E0, the same
    ! between mid-surfaces, no node edge-on or deep)
    if (r%nm%gamma <= 0.5_dp .and. r%nm%rho_inf < 0) why = why//'; or the impact''s ringing, '// &
      'which '//r%nm%describe()//' keeps undamped: rho_inf = 0.8 (generalized-alpha) damps it'
    if (r%made_contacts == 0 .and. r%dt_made_before > 0) then
      ! (a hoop hopping on a floor, its steps halved to 0.25 ms: 0.23% in the step that grew
      ! back to 0.5 ms, its strain energy alternating for ten steps after)
      why = 'with no contact, in a step that had grown back to '//rtoa(r%dt_made)//' s after cuts to '// &
            rtoa(r%dt_made_before)//' s: the start acceleration of the shorter steps rang in the longer '// &
            'one; take a shorter dt (the cuts say how much shorter), or give a tolerance (&run)'
    else if (r%made_contacts == 0 .and. r%touch_made > 0 .and. &
             r%t_made - r%touch_made <= released_steps*r%dt_made*(1 + 1e-9_dp)) then
      ! (a ball let go by a wall under generalized-alpha made 0.33% in its second free step,
      ! and the warning spoke of a spinning shell's breathing)
      why = 'with no contact, '//itoa(nint((r%t_made - r%touch_made)/r%dt_made))//' steps after one '// &
            'was let go (at t = '//rtoa(r%touch_made)//' s): the scheme''s acceleration carries '// &
            'the contact''s force into the steps after its release, and energy the contact '// &
            'took comes back there; a shorter dt shortens it'
    else if (r%made_contacts == 0) then
      why = 'with no contact, the time scheme made it over a motion its steps do not follow, '// &
            'as a spinning thin shell''s breathing under steps longer than its period (a stiff '// &
            'shell holds much energy in a small error); '
      if (r%sc%tol > 0) then   ! (with moving obstacles or pressures: not bounded step by step)
        why = why//'take a smaller tolerance'
      else
        why = why//'take a shorter dt, or give a tolerance (&run), which also bounds the '// &
              'energy a step makes while no contact is active'
      end if
    else if (allocated(r%contact)) then
      if (r%contact%opt%compliant) then   ! (a spring whose steps are too long for it)
        tc = contact_time(r%deck, r%model, b)
        why = 'the compliant contact''s time pi sqrt(rho h / stiffness) is '// &
              rtoa(tc/r%dt_made)//' steps of that step ('//rtoa(r%dt_made)//' s) for body '''// &
              trim(r%model%body(b)%name)//'''; take '//shorter//' or a lower stiffness'
      end if
    end if
    write (0, '(a)') 'warning: the step to t = '//rtoa(r%t_made)//' s made '//made//', with '// &
      count_of(r%made_contacts, 'contact', 'contacts')//' active at its start or end: '//why
  end subroutine warn_energy

  !> The energy balance's terms that the scene has: friction's, moving obstacles', a
  !> compliant contact's; with corrections, a hard contact's velocity corrections' (the
  !> printed balance: a step's energy is judged with them in the remainder, as it was tuned)
  function balance_terms(deck, contact, corrections) result(terms)
    type(deck_t), intent(in) :: deck
    type(contact_t), intent(in), optional :: contact
    logical, intent(in), optional :: corrections
    type(energy_term_t), allocatable :: terms(:)
    allocate (terms(0))
    if (.not. present(contact)) return
    if (any(contact%mu_d > 0)) terms = [terms, energy_term_t('dissipated by friction', &
                                                             sum(contact%friction_work))]
    if (moving_obstacles(deck, .true.)) &
      terms = [terms, energy_term_t('taken from moving obstacles', -contact%obstacle_work, &
                                                          source=.true.)]
    if (contact%opt%compliant) then
      terms = [terms, energy_term_t('held in the contact stiffness', sum(pair_stored_energy(contact)))]
    else if (present(corrections)) then
      if (corrections) terms = [terms, energy_term_t('taken out by the velocity corrections', &
                                                     sum(contact%correction_loss))]
    end if
  end function balance_terms

  logical function moving_obstacles(deck, use_contact)
    type(deck_t), intent(in) :: deck
    logical, intent(in) :: use_contact
    integer :: k
    moving_obstacles = use_contact .and. any([(any(deck%obstacles(k)%velocity /= 0), &
                                               k=1, size(deck%obstacles))])
  end function moving_obstacles
end module casca_run_watch
