!> Coulomb friction on the active constraints (static coefficient mu_s, dynamic mu_d per
!> pair). A constraint sticks (two Lagrange rows: no relative tangential displacement over
!> the step) or slides (a force mu_d |lambda| against its slip direction s, held through the
!> step). The return mapping between the two is an active-set change, made where Newton has
!> converged, like the release of a tensile multiplier:
!>   stick -> slip  when the stick force exceeds mu_s |lambda|; s along the stick force's
!>                  opposite (the way the node would go);
!>   slip -> stick  when the node's relative slip over the step turns against s (it stopped).
!> A constraint that went from slip back to stick in a step and is pushed past the cone again
!> slides for the rest of the step (its direction from the last stick force): the step ends
!> inside Coulomb's cone rather than cycling (a sliding ring's contact node did).
!> After an accepted step a sliding constraint takes its step's slip direction for the next
!> and adds mu_d |lambda| times its slip to the pair's dissipated energy.
module casca_contact_friction
  use casca_kinds, only: dp
  use casca_contact, only: contact_t, stick, slip
  use casca_contact_rows, only: slip_force
  implicit none
  private
  public :: friction_on, friction_update, friction_step_done, pair_tangential_force

contains

  !> Whether pair p has friction now (dynamic steps only: x_start is set)
  pure logical function friction_on(c, p)
    type(contact_t), intent(in) :: c
    integer, intent(in) :: p
    friction_on = allocated(c%x_start) .and. (c%mu_d(p) > 0 .or. c%mu_s(p) > 0)
  end function friction_on

  !> Stick/slip changes at the converged iterate; changed: how many.
  subroutine friction_update(c, changed)
    type(contact_t), intent(inout) :: c
    integer, intent(out) :: changed
    integer :: k
    real(dp) :: f(3)
    changed = 0
    do k = 1, c%nact
      associate (a => c%act(k))
        select case (a%grip)
        case (stick)
          f = a%lt(1)*a%t(:, 1) + a%lt(2)*a%t(:, 2)   ! minus the stick force on the node
          if (norm2(f) > c%mu_s(a%pair)*max(-a%lambda, 0._dp)) then
            a%grip = slip; a%s = f/norm2(f); a%lt = 0
            changed = changed + 1; a%flips = a%flips + 1
          end if
        case (slip)
          if (dot_product(a%ut, a%s) < 0 .and. a%flips < 2) then
            a%grip = stick; a%lt = 0
            changed = changed + 1; a%flips = a%flips + 1
          end if
        end select
      end associate
    end do
    if (changed > 0) c%changes = c%changes + 1
  end subroutine friction_update

  !> After an accepted step: sliding constraints turn s to their slip and add its work.
  subroutine friction_step_done(c)
    type(contact_t), intent(inout) :: c
    integer :: k
    do k = 1, c%nact
      associate (a => c%act(k))
        if (a%grip /= slip) cycle
        c%friction_work(a%pair) = c%friction_work(a%pair) + slip_force(c, a)*dot_product(a%ut, a%s)
        if (norm2(a%ut) > 0) a%s = a%ut/norm2(a%ut)
      end associate
    end do
  end subroutine friction_step_done

  !> Per pair: the magnitude of the resultant tangential (friction) force on its impactor
  pure function pair_tangential_force(c) result(ft)
    type(contact_t), intent(in) :: c
    real(dp) :: ft(c%npairs), f(3, c%npairs)
    integer :: k
    f = 0
    do k = 1, c%nact
      associate (a => c%act(k))
        if (a%grip == stick) f(:, a%pair) = f(:, a%pair) - a%lt(1)*a%t(:, 1) - a%lt(2)*a%t(:, 2)
        if (a%grip == slip) f(:, a%pair) = f(:, a%pair) - slip_force(c, a)*a%s
      end associate
    end do
    ft = norm2(f, dim=1)
  end function pair_tangential_force
end module casca_contact_friction
