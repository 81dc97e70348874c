!> Energy and momentum of a state: kinetic energy, strain energy, work of the dead loads and
!> of the follower pressures (p (V - V0) on closed surfaces, a sum along the states on open
!> ones) and of the moments (a sum along the states: casca_follower_loads),
!> linear and angular momentum, all from the constant consistent mass (no lumping); kinetic
!> and strain energy also per body, the totals being their sums.
module casca_accounting
  use casca_kinds, only: dp
  use casca_model, only: model_t, dof
  use casca_assembly, only: assembly_t, strain_energy_local
  use casca_follower_loads, only: pressure_work_local, follower_path_local
  use casca_newmark, only: state_t
  use casca_mpi, only: sum_all
  use casca_vectors, only: cross
  use casca_strings, only: rtoa, ftoa
  implicit none
  private
  public :: balance_t, energy_term_t, account, gravity_load, balance_summary, energy_balance, &
            balance_remainder, energy_put

  type :: balance_t
    real(dp) :: kinetic = 0, strain = 0, work = 0, total = 0
    real(dp) :: p(3) = 0, l(3) = 0
    !> the momenta's scale when p sums to 0: the bodies' sqrt(2 m K) summed, at least their |p|
    !> (two bodies thrown at each other, a body spinning in place)
    real(dp) :: p_bodies = 0
    real(dp), allocatable :: body_kinetic(:), body_strain(:)   !< (nbody); kinetic, strain: sums
    !> the work at load factor 1 of the pressures on open surfaces and of the moments, summed
    !> from q0 along the states
    !> accounted (one straight segment each) to q_path: carried from state to state (and in the
    !> checkpoint), as it is no function of the state
    real(dp) :: path_work = 0
    real(dp), allocatable :: q_path(:)
  end type balance_t

  !> A named share of the initial energy taken out of the bodies (positive: removed), for
  !> energy_balance: friction, work done on obstacles, ... A source (the work of moving
  !> obstacles) is printed as what it gave, -value, as the work of loads is
  type :: energy_term_t
    character(len=:), allocatable :: name
    real(dp) :: value = 0
    logical :: source = .false.
  end type energy_term_t

contains

  !> fext: the dead load; q0: the state where its work is zero; factor: the pressures'
  !> load factor (statics; default 1); bal: the balance of the state accounted before (its
  !> path_work, q_path; none: from q0), overwritten with st's. The pressures' and moments'
  !> work is factor times their work at factor 1 along the path, as the dead loads' fext .
  !> (q - q0) at the current factor in statics: p (V - V0) on a closed surface (the pressure
  !> is conservative there: exact, restart-proof), and on an open one, whose p (V - V0)
  !> depends on the origin, and for a moment, whose angle is known modulo 2 pi, the sum over
  !> the segments from state to state (follower_path_local).
  subroutine account(model, asm, st, fext, q0, bal, factor)
    type(model_t), intent(in) :: model
    type(assembly_t), intent(in) :: asm
    type(state_t), intent(in) :: st
    real(dp), intent(in) :: fext(:), q0(:)
    type(balance_t), intent(inout) :: bal
    real(dp), intent(in), optional :: factor
    real(dp) :: x(3, 20), v(3, 20), mv(3, 20), lf
    !> kinetic (nbody), strain (nbody), L, closed pressure work, p (3 nbody), open pressure work
    real(dp), allocatable :: s(:)
    integer :: i, e, p, b, nb, pb

    nb = model%nbody
    allocate (s(5*nb + 5))
    s = 0
    lf = 1
    if (present(factor)) lf = factor
    s(2*nb + 4) = pressure_work_local(model, asm%owned, st%q, q0, lf)
    if (.not. allocated(bal%q_path)) then
      bal%path_work = 0; bal%q_path = q0
    end if
    s(5*nb + 5) = follower_path_local(model, asm%owned, bal%q_path, st%q)
    call strain_energy_local(model, asm, st%q, s(nb + 1:2*nb))
    do i = 1, size(asm%owned)   ! every body: frozen ones move too
      e = asm%owned(i)
      call vectors(st%q, e, x)
      call vectors(st%qd, e, v)
      mv = matmul(v, model%emass(:, :, e))
      b = model%elem_body(e)
      s(b) = s(b) + 0.5_dp*sum(v*mv)
      pb = 2*nb + 4 + 3*(b - 1)   ! (the body's momentum; the total is their sum)
      s(pb + 1:pb + 3) = s(pb + 1:pb + 3) + sum(mv(:, 1:10), dim=2)
      do p = 1, 20
        s(2*nb + 1:2*nb + 3) = s(2*nb + 1:2*nb + 3) + cross(x(:, p), mv(:, p))
      end do
    end do
    call sum_all(s)
    bal%body_kinetic = s(1:nb); bal%body_strain = s(nb + 1:2*nb)
    bal%kinetic = sum(bal%body_kinetic); bal%strain = sum(bal%body_strain)
    bal%l = s(2*nb + 1:2*nb + 3)
    bal%p = sum(reshape(s(2*nb + 5:5*nb + 4), [3, nb]), dim=2)
    bal%p_bodies = sum(sqrt(2*model%body(:)%mass*s(1:nb)))
    bal%path_work = bal%path_work + s(5*nb + 5); bal%q_path = st%q
    bal%work = dot_product(fext, st%q - q0) + s(2*nb + 4) + lf*bal%path_work
    bal%total = bal%kinetic + bal%strain - bal%work
  contains
    !> the 20 vector parameters (Y^l, G^l) of element e from a full-length vector
    subroutine vectors(a, ee, w)
      real(dp), intent(in) :: a(:)
      integer, intent(in) :: ee
      real(dp), intent(out) :: w(3, 20)
      integer :: l, n
      do l = 1, 10
        n = model%conn(l, ee)
        w(:, l) = a(dof(n, 1):dof(n, 3))
        w(:, 10 + l) = a(dof(n, 4):dof(n, 6))
      end do
    end subroutine vectors
  end subroutine account

  !> Consistent nodal load of the body force rho*g: M applied to a uniform translation.
  subroutine gravity_load(model, f)
    type(model_t), intent(in) :: model
    real(dp), intent(out) :: f(:)
    integer :: e, l, n
    real(dp) :: m(20, 20)
    f = 0
    do e = 1, model%nelem
      m = model%emass(:, :, e)
      do l = 1, 10
        n = model%conn(l, e)
        associate (g => model%body(model%elem_body(e))%gravity)
          f(dof(n, 1):dof(n, 3)) = f(dof(n, 1):dof(n, 3)) + g*sum(m(l, 1:10))
          f(dof(n, 4):dof(n, 6)) = f(dof(n, 4):dof(n, 6)) + g*sum(m(10 + l, 1:10))
        end associate
      end do
    end do
  end subroutine gravity_load

  !> What the run kept, from the state first accounted (b0) to b: the drift of the linear
  !> momentum (of |p0|, or of the bodies' sqrt(2 m K) summed when larger: two bodies thrown
  !> at each other, or a hoop spinning in place, have p0 = 0), of the angular momentum (of |L0|, or of that momentum scale times the
  !> scene size when L0 is smaller) and the change of the total energy (of E0). Contact forces keep both
  !> momenta; the Newmark step itself keeps the linear one only: its angular momentum
  !> drifts with dt (docs/method.md), which is why the figure is printed.
  !> external: restraints, loads or obstacles act, so the momenta change by design and the
  !> figures are changes, not drifts.
  function balance_summary(b0, b, length, external) result(line)
    type(balance_t), intent(in) :: b0, b
    real(dp), intent(in) :: length
    logical, intent(in) :: external
    character(len=:), allocatable :: line
    character(len=200) :: buf
    real(dp) :: pref, lref
    pref = max(norm2(b0%p), b0%p_bodies, tiny(1._dp))
    lref = max(norm2(b0%l), pref*length)
    if (external) then   ! (absolute: the bodies may start at rest)
      write (buf, '(a,es9.2,a,es9.2,a,es11.4,a)') 'changed by supports, loads or obstacles: linear '// &
        'momentum by ', norm2(b%p - b0%p), ' N s, angular momentum by ', norm2(b%l - b0%l), &
        ' N m s; energy by ', b%total - b0%total, ' J'
    else
      write (buf, '(a,es8.1,a,es8.1,a,f8.5)') 'kept: linear momentum to ', norm2(b%p - b0%p)/pref, &
        ', angular momentum to ', norm2(b%l - b0%l)/lref, '; energy E/E0 = ', &
        b%total/max(abs(b0%total), tiny(1._dp))
    end if
    line = trim(buf)
  end function balance_summary

  !> E0 - (kinetic + strain - work + the extra terms) at state b: what the time integrator
  !> and the contact removed (energy_balance)
  pure real(dp) function balance_remainder(b0, b, extra) result(rest)
    type(balance_t), intent(in) :: b0, b
    type(energy_term_t), intent(in), optional :: extra(:)
    integer :: k
    rest = b0%total - (b%kinetic + b%strain - b%work)
    if (.not. present(extra)) return
    do k = 1, size(extra)
      rest = rest - extra(k)%value
    end do
  end function balance_remainder

  !> Where the initial energy E0 (b0%total) went by state b: kinetic, strain, minus the work of
  !> the loads, the extra terms given (each an energy taken out of the bodies), and what is
  !> left over, E0 - (kinetic + strain - work + extras): the energy removed by the time
  !> integrator (beta = 1, gamma = 1.5 damps) and by the contact (the releases and the velocity
  !> correction). It is a remainder, not a measured dissipation: it also holds every error of
  !> the other terms.
  function energy_balance(b0, b, extra, held) result(line)
    type(balance_t), intent(in) :: b0, b
    type(energy_term_t), intent(in), optional :: extra(:)
    real(dp), intent(in), optional :: held   !< the most energy the bodies held (energy_put)
    character(len=:), allocatable :: line
    real(dp) :: rest, put
    character(len=:), allocatable :: what
    integer :: k
    rest = balance_remainder(b0, b, extra)
    line = 'energy balance: E0 = '//rtoa(b0%total)//' J, kinetic '//rtoa(b%kinetic)//', strain '// &
           rtoa(b%strain)//', work of loads '//rtoa(b%work)
    if (present(extra)) then
      do k = 1, size(extra)
        line = line//', '//extra(k)%name//' '//rtoa(merge(-1, 1, extra(k)%source)*extra(k)%value)
      end do
    end if
    line = line//', removed by the time integrator and contact '//rtoa(rest)
    call energy_put(b0, b, extra, put, what, held)
    if (abs(rest) < 1e6_dp*put) then   ! (not of an E0 that is zero or nearly)
      line = line//' ('//ftoa(100*rest/put)//'% of '//what//')'
    end if
  end function energy_balance

  !> All the energy put in by state b, what the remainder is a share of, and its name: E0,
  !> the loads' work when positive, the sources' (of E0 alone, a plate dropped onto a floor
  !> under gravity had 102% of it removed); or the most the bodies held (held) where that
  !> is over twice as much: a run started at rest whose loads' net work is small at its end
  !> (a ball dropped and bounced back up: 11.6% of the net work for 3.4% of its impact energy)
  pure subroutine energy_put(b0, b, extra, put, what, held)
    type(balance_t), intent(in) :: b0, b
    type(energy_term_t), intent(in), optional :: extra(:)
    real(dp), intent(out) :: put
    character(len=:), allocatable, intent(out) :: what
    real(dp), intent(in), optional :: held
    integer :: k
    put = abs(b0%total) + max(b%work, 0._dp)
    what = 'E0'
    if (b%work > 0) what = 'E0 and the loads'' work'
    if (present(extra)) then
      do k = 1, size(extra)
        if (extra(k)%source .and. extra(k)%value < 0) then   ! (a source's value is minus what it gave)
          put = put - extra(k)%value; what = 'E0 and the work put in'
        end if
      end do
    end if
    if (present(held)) then
      if (held > 2*put) then
        put = held; what = 'the most energy the bodies held'
      end if
    end if
  end subroutine energy_put
end module casca_accounting
