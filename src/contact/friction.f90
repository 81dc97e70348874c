!> Coulomb friction on the active constraints (static coefficient mu_s, dynamic mu_d per
!> pair). A constraint sticks (two Lagrange rows: no relative tangential displacement over
!> the step) or slides (a force mu |lambda| against its slip direction s, mu = mu_d or, with
!> friction_decay, falling from mu_s to mu_d with the slip speed (rows.f90): the slip over
!> the step at each Newton iterate, friction_geometry, with its stiffness across s in
!> Newton's rows, contact_rows; held while the slip is below the slip floor). The return
!> mapping between the two is an active-set change, made where Newton has converged, like
!> the release of a tensile multiplier:
!>   stick -> slip  when the stick force exceeds mu_s |lambda|; s along the stick force's
!>                  opposite (the way the node would go);
!>   slip -> stick  when the node's relative slip over the step turns against s0, s at the
!>                  solve's start (it stopped: s itself follows the slip).
!> A constraint that went from slip back to stick in a step and is pushed past the cone again
!> slides for the rest of the step (its direction from the last stick force): the step ends
!> inside Coulomb's cone rather than cycling (a sliding ring's contact node did).
!> After an accepted step a sliding constraint adds its force times its slip to the pair's
!> dissipated energy and, in dynamics, takes its step's slip direction for the next.
module casca_contact_friction
  use casca_kinds, only: dp
  use casca_contact, only: contact_t, constraint_t, stick, slip, holds
  use casca_contact_rows, only: friction_force
  use casca_time_scheme, only: scheme_t
  implicit none
  private
  public :: friction_on, beyond_cone, friction_update, friction_hold, friction_step_done, pair_tangential_force

contains

  !> Whether pair p has friction now (dynamic steps only: x_start is set)
  pure logical function friction_on(c, p)
    type(contact_t), intent(in) :: c
    integer, intent(in) :: p
    friction_on = allocated(c%x_start) .and. (c%mu_d(p) > 0 .or. c%mu_s(p) > 0)
  end function friction_on

  !> Whether sticking constraint a's force is outside Coulomb's cone, |f_t| > mu_s |lambda|
  pure logical function beyond_cone(c, a)
    type(contact_t), intent(in) :: c
    type(constraint_t), intent(in) :: a
    beyond_cone = .false.
    if (a%grip == stick) beyond_cone = norm2(a%lt) > c%mu_s(a%pair)*max(-a%lambda, 0._dp)
  end function beyond_cone

  !> Stick/slip changes at the converged iterate; changed: how many.
  subroutine friction_update(c, changed)
    type(contact_t), intent(inout) :: c
    integer, intent(out) :: changed
    integer :: k
    real(dp) :: f(3)
    changed = 0
    do k = 1, c%set%nact
      associate (a => c%set%act(k))
        select case (a%grip)
        case (stick)
          f = a%lt(1)*a%t(:, 1) + a%lt(2)*a%t(:, 2)   ! minus the stick force on the node
          if (beyond_cone(c, a)) then
            a%grip = slip; a%s = f/norm2(f); a%s0 = a%s; a%lt = 0
            changed = changed + 1; a%flips = a%flips + 1
          end if
        case (slip)
          if (dot_product(a%ut, a%s0) < 0 .and. a%flips < 2) then
            a%grip = stick; a%lt = 0
            changed = changed + 1; a%flips = a%flips + 1
          end if
        end select
      end associate
    end do
    if (changed > 0) c%set%changes = c%set%changes + 1
  end subroutine friction_update

  !> The sliding directions are held for the rest of the solve, each at its solve's start
  !> (s0), as before they followed the slip: Newton gives up following it where it does not
  !> converge so (nodes whose slip in the step is a hundredth of their motion, about to
  !> stick, turned theirs by a radian from iterate to iterate: a ball rattling in a shell).
  !> From the next iterate on (contact_update sets s to s0): the iterate at hand was judged
  !> with the directions it has, and if it converges its sliding forces are theirs (set to s0
  !> here, a hoop's friction was booked 0.1 rad off the force that moved it)
  subroutine friction_hold(c)
    type(contact_t), intent(inout) :: c
    c%follow_slip = .false.; c%hold_slip = .true.
  end subroutine friction_hold

  !> After an accepted step (scheme ts): sliding constraints add their work and take their
  !> step's slip direction for the next (s has it already unless it was held). Newmark takes the force at the step's end and its velocity update spreads it
  !> over two steps, (1 - gamma) F_start + gamma F_end in this one: that is the force the
  !> work is counted with (the end force alone lags the kinetic energy by a step where the
  !> force jumps, as it does each time a rolling hoop hands its contact to the next node: the
  !> thesis' gamma 1.5 made 0.13% of the energy in such a step). Generalized-alpha takes the
  !> force at the step's alpha level already (its midpoint at rho_inf 1): the force itself.
  !> static: a load increment of statics, whose sliding constraints keep s as Newton left it
  !> (turned with the slip where it followed the slip). An increment's slip there is the
  !> elastic creep of a body its stuck nodes hold (up to 3e-7 m a node on the plate below,
  !> many below the slip floor, where its direction is round-off's) and, where s was held,
  !> off s, up to against it; taken as the next increment's s it turned sliding forces
  !> round, and a free plate pushed sideways at 0.967 mu N kept fewer nodes stuck at each
  !> increment (124, 14, 7 of 169) until none held it and Newton diverged, sooner with more
  !> load steps (smaller slips).
  subroutine friction_step_done(c, ts, before, static)
    type(contact_t), intent(inout) :: c
    type(scheme_t), intent(in) :: ts
    type(constraint_t), intent(in) :: before(:)   !< the active set at the step's start
    logical, intent(in), optional :: static
    integer :: k
    real(dp) :: f(3), w
    logical :: turn
    turn = .true.
    if (present(static)) turn = .not. static
    w = 1
    if (ts%alpha_m == 0 .and. ts%alpha_f == 0) w = ts%gamma
    ! a constraint that ended in the step still acts through its start force (a rolling hoop
    ! hands its contact from node to node): along its slip of the step before, unless the
    ! released constraints' forces were taken out of the start acceleration
    do k = 1, merge(0, size(before), ts%drops_released())
      associate (b => before(k))
        if (b%grip /= slip .or. holds(c%set, b%node, b%pair)) cycle
        c%friction_work(b%pair) = c%friction_work(b%pair) - dot_product((1 - w)*b%fa, b%ut)
      end associate
    end do
    do k = 1, c%set%nact
      associate (a => c%set%act(k))
        f = friction_force(c, a)
        if (a%grip == slip) then
          if (all(a%fa == 0)) a%fa = start_force(a)
          c%friction_work(a%pair) = c%friction_work(a%pair) - dot_product((1 - w)*a%fa + w*f, a%ut)
          if (turn .and. norm2(a%ut) > 0) then
            a%s = a%ut/norm2(a%ut); a%lturn = 0   ! (its turn taken: fa has the force)
          end if
        end if
        a%fa = f
      end associate
    end do
  contains
    !> a's friction force at the step's start, if its node was held then: a constraint
    !> released in the step and taken again is made anew (fa = 0), but its start force acted
    !> all the same (left out, a plate tipping over another's edge, whose sliding nodes went
    !> and came back in each step, counted 1.5 times their work: 0.2% of E0 made a step)
    function start_force(a) result(fs)
      type(constraint_t), intent(in) :: a
      real(dp) :: fs(3)
      integer :: j
      fs = 0
      do j = 1, size(before)
        if (before(j)%node == a%node .and. before(j)%pair == a%pair) fs = before(j)%fa
      end do
    end function start_force
  end subroutine friction_step_done

  !> Per pair: the magnitude of the resultant tangential (friction) force on its impactor, as
  !> it acted at the end of the last step (fa)
  pure function pair_tangential_force(c) result(ft)
    type(contact_t), intent(in) :: c
    real(dp) :: ft(c%npairs), f(3, c%npairs)
    integer :: k
    f = 0
    do k = 1, c%set%nact
      f(:, c%set%act(k)%pair) = f(:, c%set%act(k)%pair) + c%set%act(k)%fa
    end do
    ft = norm2(f, dim=1)
  end function pair_tangential_force
end module casca_contact_friction
