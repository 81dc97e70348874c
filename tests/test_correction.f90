!> The contact correction against the identities of a projection in the mass metric, on two
!> rings that overlap obliquely (so that several impactor nodes are constrained, off the
!> line of centres) with arbitrary velocities and accelerations:
!>   - the normal relative velocity and acceleration of every constraint become zero;
!>   - the linear momentum does not change;
!>   - the angular momentum changes by exactly the moment of the impulses,
!>     sum_k nu_k (x_imp - x_target(xi_k)) x n_k (zero when the two points coincide);
!>   - the kinetic energy drops by exactly -1/2 sum_k nu_k w_k (w: the normal relative
!>     velocities before), and never rises; the per-row losses the correction returns (the
!>     history's contact_loss_P) sum to that drop, computed here from the bodies' energies.
!> A lumped-mass correction fails the third (it was 1e-3 of m v0 R on the oblique rings).
program test_correction
  use casca_kinds, only: dp
  use casca_error, only: error_t
  use casca_model, only: model_t, dof, reference_state
  use casca_assembly, only: assembly_t, assembly_setup
  use casca_newmark, only: state_t
  use casca_accounting, only: balance_t, account
  use casca_contact, only: contact_t, contact_init
  use casca_contact_active_set, only: contact_update
  use casca_obstacle, only: obstacle_t
  use casca_mass_solver, only: mass_solver_t, mass_setup
  use casca_contact_correction, only: contact_correction, correction_cache_t
  use casca_vectors, only: cross
  use casca_mpi, only: mpi_start, mpi_stop
  use casca_test_rings, only: overlapping_rings
  use casca_check, only: check_le, check_true, check_summary
  implicit none

  type(model_t) :: model
  type(assembly_t) :: asm
  type(contact_t) :: c
  type(mass_solver_t) :: ms
  type(correction_cache_t) :: cache
  type(state_t) :: st
  type(balance_t) :: b0, b1
  type(error_t), allocatable :: err
  real(dp), allocatable :: zero(:), nu(:), loss(:), w0(:), w1(:), wa(:)
  real(dp) :: moment(3), scale, xt(3)
  integer :: i, k, added

  call mpi_start()
  call overlapping_rings(model)
  call assembly_setup(model, asm, err)
  call mass_setup(model, ms, err)
  if (allocated(err)) error stop 'mass'
  allocate (st%q(model%ndof), zero(model%ndof))
  call reference_state(model, st%q)
  zero = 0
  call contact_init(model, reshape([1, 2], [2, 1]), [obstacle_t ::], 1e-9_dp, .false., c)
  call contact_update(c, model, st%q, .true., added)
  call check_true('overlapping rings: several constraints found', c%set%nact >= 3)
  ! arbitrary smooth velocities and accelerations on every parameter
  st%qd = [(sin(0.37_dp*i) + 0.3_dp*cos(1.3_dp*i), i=1, model%ndof)]
  st%qdd = [(cos(0.11_dp*i), i=1, model%ndof)]
  call account(model, asm, st, zero, st%q, b0)
  w0 = normal_rates(st%qd)
  allocate (nu(c%set%nact), loss(c%set%nact))
  call contact_correction(ms, cache, c, model, st%qd, st%qdd, err, nu, loss)
  if (allocated(err)) error stop 'correction'
  call account(model, asm, st, zero, st%q, b1)
  w1 = normal_rates(st%qd); wa = normal_rates(st%qdd)
  call check_le('normal relative velocities after / before (max)', &
                maxval(abs(w1))/maxval(abs(w0)), 1e-12_dp)
  call check_le('normal relative accelerations after (max, of the velocities before)', &
                maxval(abs(wa))/maxval(abs(w0)), 1e-10_dp)
  scale = sum(abs(nu))   ! the impulses' size [N s]
  call check_le('linear momentum change / sum |nu|', norm2(b1%p - b0%p)/scale, 1e-12_dp)
  moment = 0
  do k = 1, c%set%nact
    associate (con => c%set%act(k))
      xt = 0
      do i = 1, 10
        xt = xt + con%shp(i)*st%q(dof(model%conn(i, con%elem), 1):dof(model%conn(i, con%elem), 3))
      end do
      moment = moment + nu(k)*cross(st%q(dof(con%node, 1):dof(con%node, 3)) - xt, con%n)
    end associate
  end do
  call check_le('angular momentum change vs the moment of the impulses (|diff| / sum |nu| / 1 m)', &
                norm2(b1%l - b0%l - moment)/scale, 1e-12_dp)
  call check_true('the moment of the impulses is not zero here (the test can tell)', &
                  norm2(moment)/scale > 1e-6_dp)
  call check_le('kinetic energy drop vs -1/2 nu . w (relative)', &
                abs((b0%kinetic - b1%kinetic) + 0.5_dp*dot_product(nu, w0))/(b0%kinetic - b1%kinetic), &
                1e-10_dp)
  call check_true('kinetic energy does not rise', b1%kinetic <= b0%kinetic)
  call check_le('the rows'' losses summed vs the kinetic energy drop (relative)', &
                abs(sum(loss) - (b0%kinetic - b1%kinetic))/(b0%kinetic - b1%kinetic), 1e-10_dp)
  call ms%finish()
  call check_summary()
  call mpi_stop()
contains
  !> n . (v_imp - sum_j N_j v_j) of every constraint
  function normal_rates(v) result(w)
    real(dp), intent(in) :: v(:)
    real(dp), allocatable :: w(:)
    integer :: kk, j
    allocate (w(c%set%nact))
    do kk = 1, c%set%nact
      associate (con => c%set%act(kk))
        w(kk) = dot_product(con%n, v(dof(con%node, 1):dof(con%node, 3)))
        do j = 1, 10
          w(kk) = w(kk) - con%shp(j)*dot_product(con%n, &
                  v(dof(model%conn(j, con%elem), 1):dof(model%conn(j, con%elem), 3)))
        end do
      end associate
    end do
  end function normal_rates
end program test_correction
