!> The active constraints as the equations see them: the rows of C for the saddle point (one
!> per constraint, two more for a sticking one, one more in Newton's system for a sliding
!> one), their multipliers, and the contact forces C^T lambda they carry (with the sliding
!> ones' friction).
module casca_contact_rows
  use casca_kinds, only: dp
  use casca_model, only: model_t, dof
  use casca_contact, only: contact_t, constraint_t, stick, slip, normal_compliance, normal_residual, &
                           slip_followed
  use casca_contact_projection, only: constraint_entries, constraint_row, max_row, force_point, positions, &
                                      constraint_geometry, normal_cache_t, normal_cache, across
  use casca_obstacle, only: obstacle_point
  use casca_vectors, only: cross
  use casca_time_scheme, only: scheme_t
  use casca_lapack, only: dpotrf, dpotrs
  implicit none
  private
  public :: contact_nrows, contact_newton_nrows, contact_rows, contact_multipliers, contact_set_multipliers
  public :: contact_generalized_force, contact_force_total, contact_nodal_fields, contact_max_gap
  public :: pair_stored_energy
  public :: constraint_nkinds, slip_force, friction_force, add_step_impulse, pair_forces, contact_force_points
  public :: start_friction
  public :: start_carry

contains

  !> How many rows a constraint has: kinds 0 (normal) to this less one (1, 2: stick)
  pure integer function constraint_nkinds(a)
    type(constraint_t), intent(in) :: a
    constraint_nkinds = merge(3, 1, a%grip == stick)
  end function constraint_nkinds

  !> Number of rows of the active set
  pure integer function contact_nrows(c)
    type(contact_t), intent(in) :: c
    integer :: k
    contact_nrows = sum([(constraint_nkinds(c%set%act(k)), k=1, c%set%nact)])
  end function contact_nrows

  !> Number of rows of Newton's system: the active set's, one across the slip of each
  !> sliding constraint and one along n on each rim fibre that may bend (contact_rows)
  pure integer function contact_newton_nrows(c)
    type(contact_t), intent(in) :: c
    contact_newton_nrows = contact_nrows(c) + count(c%set%act(1:c%set%nact)%grip == slip) + &
                           count(c%set%act(1:c%set%nact)%bend)
  end function contact_newton_nrows

  !> Every active constraint's force point (force_point) where the scheme takes the
  !> internal force, (1 - af) q + af qn (at q without qn). With af = 0 (Newmark) the force
  !> stays at the gap's point, as in the thesis: Newmark does not keep L anyway, and with the
  !> force point Newton's symmetric saddle matrix converges only by fixed point (a
  !> self-contact crush stalled).
  subroutine contact_force_points(c, model, af, q, qn)
    type(contact_t), intent(inout) :: c
    type(model_t), intent(in) :: model
    real(dp), intent(in) :: af, q(:)
    real(dp), intent(in), optional :: qn(:)
    real(dp), allocatable :: qf(:), xf(:, :)
    real(dp) :: gm
    integer :: k, bt, nd
    type(constraint_t) :: cf
    type(normal_cache_t) :: normals
    if (.not. af > 0) return
    if (present(qn)) then
      qf = (1 - af)*q + af*qn
    else
      qf = q
    end if
    do k = 1, c%set%nact
      associate (a => c%set%act(k))
        call force_point(model, qf, a)
        bt = c%pair(2, a%pair)
        if (bt > 0) then
          if (a%nl == 0) cycle
          ! a normal row with its lever: the gap's gradient at qf (its point, side and faces
          ! held), the midpoint rule's force for a work that is the gap's change over the step
          if (.not. allocated(xf)) then
            xf = positions(model, qf)
            if (c%opt%nodal_normal) call normal_cache(model, normals)
          end if
          cf = a   ! (normals: made and read with nodal normals only)
          call constraint_geometry(c, model, xf, qf, cf, normals, lever=.true.)
          if (cf%nl /= a%nl) cycle   ! (the same nodes; else the end's gradient)
          a%nf = cf%n; a%wgf = cf%wg; a%lgradf = cf%lgrad(:, 1:cf%nl)
          cycle
        end if
        ! an obstacle: its normal at the node's face point there (the midpoint rule's
        ! angular momentum about a cylinder's axis changes by x_mid x f, which n at the step's
        ! end, half a step's slide away, did not leave at zero: a ring spinning in a drum lost
        ! 1.4e-4 of it at 10 us, first order in dt)
        nd = a%node
        call obstacle_point(c%obstacle(-bt), c%time, qf(dof(nd, 1):dof(nd, 3)) + &
                            a%wg(1)*qf(dof(nd, 4):dof(nd, 6)), a%nf, gm)
      end associate
    end do
  end subroutine contact_force_points

  !> The multipliers of every row of Newton's system, in row order (0 across a slip: that
  !> row's multiplier is an increment's only, contact_rows)
  pure function contact_multipliers(c) result(lam)
    type(contact_t), intent(in) :: c
    real(dp), allocatable :: lam(:)
    integer :: k, r
    allocate (lam(contact_newton_nrows(c)))
    r = 0
    do k = 1, c%set%nact
      associate (a => c%set%act(k))
        r = r + 1; lam(r) = a%lambda
        if (a%grip == stick) then
          lam(r + 1:r + 2) = a%lt; r = r + 2
        else if (a%grip == slip) then
          r = r + 1; lam(r) = 0
        end if
        if (a%bend) then
          r = r + 1; lam(r) = 0
        end if
      end associate
    end do
  end function contact_multipliers

  pure subroutine contact_set_multipliers(c, lam)
    type(contact_t), intent(inout) :: c
    real(dp), intent(in) :: lam(:)
    integer :: k, r
    r = 0
    do k = 1, c%set%nact
      associate (a => c%set%act(k))
        r = r + 1; a%lambda = lam(r)
        if (a%grip == stick) then
          a%lt = lam(r + 1:r + 2); r = r + 2
        else if (a%grip == slip) then
          r = r + 1; a%lturn = lam(r)
        end if
        if (a%bend) r = r + 1
      end associate
    end do
  end subroutine contact_set_multipliers

  !> Constraint rows for MUMPS: entries (neq + r, eq) of dg_r/dq (irn > jcn), a diagonal for
  !> each multiplier (zero, or minus a compliant normal row's compliance), the rows' residuals
  !> (the gaps, less compliance times lambda), and each row's key (node and kind, element).
  !> fval: the same entries of the columns the multipliers act through: C^T where the force
  !> acts (force_point), and for a sliding constraint's normal row n - mu s there
  !> (its friction follows |lambda|; mu its sliding coefficient).
  !> A sliding constraint's force turns with its slip (s = ut / |ut|, friction_geometry):
  !> across s it is as stiff as k = mu |lambda| / |ut|, which Newton needs (without it
  !> the turn overshoots where k is as stiff as the node). That stiffness, k B_e^T C_e (e
  !> across s, B at the force's point, C at the gap's), is the row across s with compliance
  !> 1/k and no gap: eliminated, its multiplier adds it to K. The multiplier is an
  !> increment's only (0 at each iterate, contact_multipliers): the force it stands for is
  !> in s's turn at the next iterate, or after the last in friction_force (lturn). Where s
  !> is held (slip_stiffness 0) the row is empty with compliance 1, its multiplier 0.
  subroutine contact_rows(c, model, eq, neq, irn, jcn, val, gap, key, fval)
    type(contact_t), intent(in) :: c
    type(model_t), intent(in) :: model
    integer, intent(in) :: eq(:), neq
    integer, allocatable, intent(out) :: irn(:), jcn(:), key(:, :)
    real(dp), allocatable, intent(out) :: val(:), gap(:), fval(:)
    integer :: k, j, m, nd, d(max_row), r, kind, nr, ns, i
    real(dp) :: v(max_row), vs(max_row), vf(max_row), mu, ks, w, kb
    nr = contact_newton_nrows(c)
    ! (entries: 66 for the points and fibres and a diagonal per row, one more row across a
    ! slip, the levers' beside)
    m = sum([(67*(constraint_nkinds(c%set%act(k)) + merge(1, 0, c%set%act(k)%grip == slip)) + 3*c%set%act(k)%nl &
              + merge(4, 0, c%set%act(k)%bend), k=1, c%set%nact)])
    allocate (irn(m), jcn(m), val(m), gap(nr), key(2, nr), fval(m))
    m = 0; r = 0
    do k = 1, c%set%nact
      associate (a => c%set%act(k))
        do i = 0, constraint_nkinds(a) - merge(0, 1, a%grip == slip)
          kind = i
          if (a%grip == slip .and. i == 1) kind = across
          r = r + 1
          if (kind == 0) then   ! (compliant: g - lambda / k, contact_set_stiffness)
            gap(r) = normal_residual(c, a)
          else if (kind == across) then
            gap(r) = 0
          else
            gap(r) = a%gt(kind)
          end if
          key(:, r) = [4*a%node + kind, a%elem]
          if (kind == across) key(1, r) = -(4*a%node + 3)   ! (apart from every other row)
          call constraint_row(a, model, d, v, nd, kind)
          vf(1:nd) = v(1:nd)   ! (the force's own row only where it has its own point)
          if (any(a%shpf /= a%shp) .or. any(a%nf /= a%n) .or. &
              a%nl > 0) &
            call constraint_row(a, model, d, vf, nd, kind, force=.true.)
          mu = 0; ns = 0
          if (kind == 0 .and. a%grip == slip .and. a%lambda < 0) then
            mu = sliding_coefficient(c, a); key(1, r) = 4*a%node + 3
            call constraint_row(a, model, d, vs, ns, 3, force=.true.)   ! (the same points first)
          end if
          w = 1   ! (the row's weight: 0 for an empty row across a held s, or a stick row held by restraints)
          if (kind == across) then
            ks = slip_stiffness(c, a)
            if (.not. ks > 0) w = 0
          else if (kind /= 0) then   ! (its multiplier stays 0: the restraint's reaction holds it)
            if (all(eq(d(1:nd)) == 0 .or. abs(v(1:nd)) <= 1e-12_dp*maxval(abs(v(1:nd))))) then
              w = 0; gap(r) = 0
            end if
          end if
          do j = 1, nd
            if (eq(d(j)) == 0) cycle   ! prescribed parameter: no column
            m = m + 1; irn(m) = neq + r; jcn(m) = eq(d(j)); val(m) = w*v(j); fval(m) = w*vf(j)
            if (j <= ns) fval(m) = vf(j) - mu*vs(j)
          end do
          m = m + 1; irn(m) = neq + r; jcn(m) = neq + r; val(m) = 0; fval(m) = 0
          if (kind == 0) val(m) = -normal_compliance(c, a)
          if (kind /= 0 .and. w == 0) val(m) = -1   ! (an empty row: its multiplier stays)
          if (kind == across .and. w > 0) val(m) = -1/ks
        end do
        ! a rim fibre's curvature: Newton's stiffness -lambda wgg along n on the node's fibre,
        ! the row's compliance (eliminated, as across a slip; multiplier 0 at each iterate).
        ! Without it a tube crushed onto a plane, whose edge fibres came to rest where their
        ! offset's rounding begins, converged by fixed point and stopped (contraction 0.47 an
        ! iteration)
        if (a%bend) then
          r = r + 1; gap(r) = 0
          key(:, r) = [-(4*a%node + 2), a%elem]
          kb = -a%lambda*a%wgg
          w = merge(1._dp, 0._dp, kb /= 0)
          do j = 1, 3
            if (eq(dof(a%node, 3 + j)) == 0) cycle
            m = m + 1; irn(m) = neq + r; jcn(m) = eq(dof(a%node, 3 + j)); val(m) = w*a%n(j); fval(m) = val(m)
          end do
          m = m + 1; irn(m) = neq + r; jcn(m) = neq + r; val(m) = -1; fval(m) = 0
          if (kb /= 0) val(m) = -1/kb
        end if
      end associate
    end do
    irn = irn(1:m); jcn = jcn(1:m); val = val(1:m); fval = fval(1:m)
  end subroutine contact_rows

  !> The sliding force's stiffness across its slip, mu |lambda| / |ut|, where s follows the
  !> slip (friction_geometry); 0 where s is held or the force is 0
  pure real(dp) function slip_stiffness(c, a)
    type(contact_t), intent(in) :: c
    type(constraint_t), intent(in) :: a
    slip_stiffness = 0
    if (slip_followed(c, a)) slip_stiffness = slip_force(c, a)/norm2(a%ut)
  end function slip_stiffness

  !> The sliding force's multiplier on the row along s: mu |lambda| (0 unless sliding), mu
  !> the sliding coefficient (sliding_coefficient)
  pure real(dp) function slip_force(c, a)
    type(contact_t), intent(in) :: c
    type(constraint_t), intent(in) :: a
    slip_force = 0
    if (a%grip == slip) slip_force = sliding_coefficient(c, a)*max(-a%lambda, 0._dp)
  end function slip_force

  !> The coefficient of a sliding constraint: mu_d, or where its pair has a decay speed v_c
  !> (friction_decay DC = 1/v_c, LS-DYNA's), mu_d + (mu_s - mu_d) exp(-|v| / v_c) with v its
  !> slip speed, its slip over the step at this iterate over dt. A node that starts to slide
  !> keeps about mu_s until it moves: dropped to mu_d at once, the edge nodes of a plate at
  !> rest on an incline, which carry its bending and pass mu_s though the plate is well inside
  !> the cone, shed their load row after row and the whole plate slid at mu_d
  !> (docs/performance.md). Statics have no time: mu_d. The coefficient's fall with the slip
  !> is not in Newton's rows (a negative stiffness along s): followed by fixed point, for a
  !> body sliding under its weight each iterate's error shrinks by about
  !> (mu_s - mu_d) g_n beta dt exp(-|v| / v_c) / v_c, g_n the weight's normal part per mass:
  !> 0.1 to 0.2 on that plate at DC 100 s/m and dt 1 ms
  pure real(dp) function sliding_coefficient(c, a)
    type(contact_t), intent(in) :: c
    type(constraint_t), intent(in) :: a
    sliding_coefficient = c%mu_d(a%pair)
    if (.not. (c%v_decay(a%pair) > 0 .and. c%dt > 0)) return
    sliding_coefficient = sliding_coefficient + (c%mu_s(a%pair) - c%mu_d(a%pair))* &
                          exp(-norm2(a%ut)/c%dt/c%v_decay(a%pair))
  end function sliding_coefficient

  !> f = C^T lambda (ndof) with the friction: minus the contact forces, on the fibres too
  !> between faces, every row where the force acts (force_point)
  subroutine contact_generalized_force(c, model, f)
    type(contact_t), intent(in) :: c
    type(model_t), intent(in) :: model
    real(dp), intent(out) :: f(:)
    integer :: k, nd, d(max_row)
    real(dp) :: v(max_row)
    f = 0
    do k = 1, c%set%nact
      associate (a => c%set%act(k))
        call constraint_row(a, model, d, v, nd, force=.true.)
        f(d(1:nd)) = f(d(1:nd)) + a%lambda*v(1:nd)
        if (a%grip == stick) then
          call constraint_row(a, model, d, v, nd, 1, force=.true.)
          f(d(1:nd)) = f(d(1:nd)) + a%lt(1)*v(1:nd)
          call constraint_row(a, model, d, v, nd, 2, force=.true.)
          f(d(1:nd)) = f(d(1:nd)) + a%lt(2)*v(1:nd)
        else if (a%grip == slip) then
          call constraint_row(a, model, d, v, nd, 3, force=.true.)
          f(d(1:nd)) = f(d(1:nd)) + slip_force(c, a)*v(1:nd)
        end if
      end associate
    end do
  end subroutine contact_generalized_force

  !> Total normal contact force (sum of the compressive multipliers).
  pure real(dp) function contact_force_total(c)
    type(contact_t), intent(in) :: c
    contact_force_total = -sum(c%set%act(1:c%set%nact)%lambda)
  end function contact_force_total

  !> Largest residual of the active rows: |gap| (less compliance times lambda) and the stick
  !> rows' tangential displacement
  pure real(dp) function contact_max_gap(c)
    type(contact_t), intent(in) :: c
    integer :: k
    contact_max_gap = 0
    do k = 1, c%set%nact
      associate (a => c%set%act(k))
        contact_max_gap = max(contact_max_gap, abs(normal_residual(c, a)))
        if (a%grip == stick) contact_max_gap = max(contact_max_gap, maxval(abs(a%gt)))
      end associate
    end do
  end function contact_max_gap

  !> Per pair, the energy a compliant contact holds at its gaps, k g^2 / 2 over the
  !> penetrating active constraints [J] (as the strain energy, at the step's end)
  pure function pair_stored_energy(c) result(e)
    type(contact_t), intent(in) :: c
    real(dp) :: e(c%npairs)
    integer :: k
    e = 0
    do k = 1, c%set%nact
      associate (a => c%set%act(k))
        if (c%opt%compliance(a%node) > 0) e(a%pair) = e(a%pair) + 0.5_dp*min(a%gap, 0._dp)**2/c%opt%compliance(a%node)
      end associate
    end do
  end function pair_stored_energy

  !> The contact force on each pair's impactor (3, npairs): normal and friction
  pure function pair_forces(c) result(f)
    type(contact_t), intent(in) :: c
    real(dp) :: f(3, c%npairs)
    integer :: k
    f = 0
    do k = 1, c%set%nact
      associate (a => c%set%act(k))
        f(:, a%pair) = f(:, a%pair) + node_force(c, a)
      end associate
    end do
  end function pair_forces

  !> After an accepted step (scheme ts): add each pair's impulse on its impactor as the
  !> integrator applied it, and the moving obstacles' work from it. The step changes the
  !> momentum by dt ((1 - gamma) A_start + gamma A_end) + C^T nu: A_start the contact's share
  !> of M a at the start (the last step's, with its acceleration corrections mu: c%carry),
  !> less the forces (normal and friction) of the constraints released taken out of it
  !> (newmark.f90);
  !> A_end = (F_end - alpha_m A_start)/(1 - alpha_m) with F_end the end forces (pair_forces
  !> as Newton left them: f_end); nu the velocity correction's impulses, in row order, along
  !> the normals it took (Newmark: A_end = F_end). Every normal part is along the normal of
  !> the row that applied it: nf for the forces (n but on curved obstacles under
  !> generalized-alpha, and with a lever), point_normal for the correction's (build_rows).
  !> (dt F_end summed over the steps is off by Newton's tolerance; this is exact.) loss: the
  !> kinetic energy the velocity correction took out, per row (contact_correction), summed
  !> into each pair's correction_loss.
  subroutine add_step_impulse(c, ts, released, nu, f_end, loss)
    type(contact_t), intent(inout) :: c
    type(scheme_t), intent(in) :: ts
    type(constraint_t), intent(in) :: released(:)
    real(dp), intent(in) :: nu(:), f_end(:, :), loss(:)
    real(dp) :: j(3, c%npairs), a_end(3, c%npairs), mu(3, c%npairs), dt, g
    integer :: k, r, t
    dt = ts%dt; g = ts%gamma
    do k = 1, size(released)
      associate (a => released(k))
        c%carry(:, a%pair) = c%carry(:, a%pair) - a%mu*point_normal(a) + &
                             (a%lambda*a%nf - start_friction(a))/(1 - ts%alpha_m)
      end associate
    end do
    j = 0; mu = 0
    r = 0
    do k = 1, c%set%nact
      associate (a => c%set%act(k))
        j(:, a%pair) = j(:, a%pair) + nu(r + 1)*point_normal(a)
        c%correction_loss(a%pair) = c%correction_loss(a%pair) + sum(loss(r + 1:r + constraint_nkinds(a)))
        mu(:, a%pair) = mu(:, a%pair) + a%mu*point_normal(a)
        if (a%grip == stick) then
          j(:, a%pair) = j(:, a%pair) + nu(r + 2)*a%t(:, 1) + nu(r + 3)*a%t(:, 2)
          mu(:, a%pair) = mu(:, a%pair) + a%mut(1)*a%t(:, 1) + a%mut(2)*a%t(:, 2)
        end if
        r = r + constraint_nkinds(a)
      end associate
    end do
    a_end = ts%end_force_weight(f_end, c%carry)
    j = j + dt*((1 - g)*c%carry + g*a_end)
    c%carry = a_end + mu
    c%impulse = c%impulse + j
    do k = 1, c%npairs
      t = c%pair(2, k)
      if (t <= 0) c%obstacle_work = c%obstacle_work + dot_product(j(:, k), c%obstacle(-t)%velocity)
    end do
  end subroutine add_step_impulse

  !> The contact's share of M a at the start (c%carry) when bodies start held by their
  !> contacts (start_acceleration gives them a = 0): share(:, b) is what the pairs must give
  !> body b between them (its weight reversed; 0 for a free body without gravity). Per pair,
  !> the least forces that give every free body of the pairs near contact its share, with
  !> obstacles and restrained bodies as the ground: f = A^T (A A^T)^-1 share, A the pairs'
  !> incidence (+1 on the impactor, -1 on the target). Exact where those pairs form a tree (a
  !> plate on a floor, a stack of plates); where they close a loop the split is the
  !> stiffnesses', which the start does not know, and this one is a plausible one (each
  !> body's total is still exact). A group nothing grounds keeps 0.
  subroutine start_carry(c, near, share, ground)
    type(contact_t), intent(inout) :: c
    logical, intent(in) :: near(:)            !< per pair: near contact at the start
    real(dp), intent(in) :: share(:, :)       !< (3, nbody)
    logical, intent(in) :: ground(:)          !< per body: restrained
    integer :: row(size(ground)), nb, k, i, j, info
    real(dp), allocatable :: l(:, :), y(:, :)
    row = 0; nb = 0
    do k = 1, c%npairs
      if (.not. near(k)) cycle
      do j = 1, 2
        i = c%pair(j, k)
        if (i <= 0) cycle
        if (ground(i) .or. row(i) > 0) cycle
        nb = nb + 1; row(i) = nb
      end do
    end do
    if (nb == 0) return
    allocate (l(nb, nb), y(nb, 3))
    l = 0; y = 0
    do i = 1, size(ground)
      if (row(i) > 0) y(row(i), :) = share(:, i)
    end do
    do k = 1, c%npairs
      if (.not. near(k)) cycle
      call add_incidence(row(c%pair(1, k)), row(c%pair(1, k)), 1._dp)
      if (c%pair(2, k) > 0) then
        call add_incidence(row(c%pair(2, k)), row(c%pair(2, k)), 1._dp)
        call add_incidence(row(c%pair(1, k)), row(c%pair(2, k)), -1._dp)
        call add_incidence(row(c%pair(2, k)), row(c%pair(1, k)), -1._dp)
      end if
    end do
    call dpotrf('L', nb, l, nb, info)
    if (info /= 0) return
    call dpotrs('L', nb, 3, l, nb, y, nb, info)
    if (info /= 0) return
    do k = 1, c%npairs
      if (.not. near(k)) cycle
      c%carry(:, k) = y_of(c%pair(1, k)) - y_of(c%pair(2, k))
    end do
  contains
    subroutine add_incidence(a, b, v)
      integer, intent(in) :: a, b
      real(dp), intent(in) :: v
      if (a > 0 .and. b > 0) l(a, b) = l(a, b) + v
    end subroutine add_incidence
    function y_of(body) result(v)
      integer, intent(in) :: body
      real(dp) :: v(3)
      v = 0
      if (body > 0) then
        if (row(body) > 0) v = y(row(body), :)
      end if
    end function y_of
  end subroutine start_carry

  !> The normal the velocity correction's row takes on the node (row_factors' point): n with
  !> a lever (nf is then the force's, at the scheme's internal-force configuration), else nf
  pure function point_normal(a) result(n)
    type(constraint_t), intent(in) :: a
    real(dp) :: n(3)
    n = merge(a%n, a%nf, a%nl > 0)
  end function point_normal

  !> A sliding constraint's friction force as the step's start acceleration has it (the force
  !> fa the last step left; 0: not sliding, a sticking one's is in its rows): a constraint
  !> released in the step takes it out of there with its normal force
  pure function start_friction(a) result(f)
    type(constraint_t), intent(in) :: a
    real(dp) :: f(3)
    f = 0
    if (a%grip == slip) f = a%fa
  end function start_friction

  !> The contact force on the constraint's node: normal and friction
  pure function node_force(c, a) result(f)
    type(contact_t), intent(in) :: c
    type(constraint_t), intent(in) :: a
    real(dp) :: f(3)
    f = -a%lambda*a%nf + friction_force(c, a)   ! (along the normal the force acts on)
  end function node_force

  !> The friction force on the constraint's node (0 without friction) at the iterate Newton
  !> accepted: a sliding one's along s, and its turn over the last increment (lturn), which
  !> moved the bodies as much (left out, a hoop rolling with friction, its slip 1e-8 m in a
  !> step, had 1.6e-8 of its impulse unaccounted for)
  pure function friction_force(c, a) result(f)
    type(contact_t), intent(in) :: c
    type(constraint_t), intent(in) :: a
    real(dp) :: f(3), e(3)
    f = 0
    if (a%grip == stick) f = -a%lt(1)*a%t(:, 1) - a%lt(2)*a%t(:, 2)
    if (a%grip == slip) then
      f = -slip_force(c, a)*a%s
      e = cross(a%n, a%s)   ! (the row across the slip's direction, row_factors)
      if (norm2(e) > 0) f = f - a%lturn*e/norm2(e)
    end if
  end function friction_force

  !> Nodal contact force (3, nnode) on the bodies (both sides of a pair): normal and friction
  pure subroutine contact_nodal_fields(c, model, force)
    type(contact_t), intent(in) :: c
    type(model_t), intent(in) :: model
    real(dp), intent(out) :: force(:, :)
    integer :: k, j, nodes(11), nn
    real(dp) :: w(11), f(3)
    force = 0
    do k = 1, c%set%nact
      associate (a => c%set%act(k))
        f = node_force(c, a)
        call constraint_entries(a, model, nodes, w, nn, force=.true.)
        do j = 1, nn
          force(:, nodes(j)) = force(:, nodes(j)) + w(j)*f
        end do
      end associate
    end do
  end subroutine contact_nodal_fields
end module casca_contact_rows
