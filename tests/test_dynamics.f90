!> Newmark dynamics against independent answers: the first bending frequency of a cantilever
!> strip (Euler-Bernoulli), and the free flight of a spinning closed sphere (linear momentum
!> exactly kept with gamma = 1/2; angular momentum and energy drift shrink with dt).
!> Argument "write FILE" stores the free-flight positions, "compare FILE" compares them with
!> this run's (the 1-rank / 2-rank agreement test).
program test_dynamics
  use casca_kinds, only: dp, pi
  use casca_error, only: error_t
  use casca_mesh, only: mesh_t
  use casca_mesh_generators, only: mesh_plate, mesh_sphere
  use casca_model, only: model_t, model_add_body, model_finalize, dof, reference_state
  use casca_assembly, only: assembly_t, assembly_setup
  use casca_linear_system, only: linear_system_t
  use casca_newton, only: newton_opts_t, newton_report_t, newton_solve
  use casca_newmark, only: state_t, newmark_step
  use casca_time_scheme, only: scheme_t, newmark_scheme
  use casca_accounting, only: balance_t, account
  use casca_mpi, only: mpi_start, mpi_stop, is_root, n_ranks
  use casca_vectors, only: cross
  use casca_check, only: check_le, check_close, check_true, check_summary
  implicit none

  character(len=256) :: mode, path
  real(dp) :: drift_l(2), drift_e(2), dp_max(2)
  real(dp), allocatable :: qfinal(:), qref(:)
  integer :: u, ios

  call mpi_start()
  mode = ''; path = ''
  if (command_argument_count() >= 2) then
    call get_command_argument(1, mode); call get_command_argument(2, path)
  end if

  if (mode == '') call free_vibration()

  call free_flight(1e-4_dp, 200, drift_l(1), drift_e(1), dp_max(1), qfinal)
  if (is_root()) print '(a,3es11.3)', 'free flight dt:   max |dp|/|p|, |dL|/|L|, |dE|/E = ', &
    dp_max(1), drift_l(1), drift_e(1)
  call check_le('free flight: linear momentum kept (max |p - p0| / |p0|, 200 steps)', &
                dp_max(1), 1e-10_dp)

  select case (mode)
  case ('')
    call free_flight(0.5e-4_dp, 400, drift_l(2), drift_e(2), dp_max(2))
    if (is_root()) print '(a,3es11.3)', 'free flight dt/2: max |dp|/|p|, |dL|/|L|, |dE|/E = ', &
      dp_max(2), drift_l(2), drift_e(2)
    call check_le('free flight dt/2: linear momentum kept', dp_max(2), 1e-10_dp)
    call check_le('free flight: angular momentum drift at dt/2 over drift at dt', &
                  drift_l(2)/drift_l(1), 0.75_dp)
    call check_le('free flight: energy drift at dt/2 over drift at dt', &
                  drift_e(2)/drift_e(1), 0.75_dp)
  case ('write')
    if (is_root()) then
      open (newunit=u, file=trim(path), form='unformatted', access='stream', status='replace')
      write (u) size(qfinal), qfinal
      close (u)
    end if
  case ('compare')
    allocate (qref(size(qfinal)))
    open (newunit=u, file=trim(path), form='unformatted', access='stream', status='old', &
          iostat=ios)
    call check_true('reference positions from the 1-rank run are readable', ios == 0)
    if (ios == 0) then
      read (u) ios, qref   ! size, then positions
      close (u)
      print '(a,i0,a,es10.3)', 'ranks: ', n_ranks, ', max |q - q_1rank| / max |q| = ', &
        maxval(abs(qfinal - qref))/maxval(abs(qref))
      call check_le('1 and 2 ranks give the same positions (relative)', &
                    maxval(abs(qfinal - qref))/maxval(abs(qref)), 1e-9_dp)
    end if
  end select

  call check_summary()
  call mpi_stop()

contains

  !> Cantilever strip released from a small static tip deflection; period from the zero
  !> crossings of the tip deflection (trapezoidal rule, dt = T/200).
  subroutine free_vibration()
    real(dp), parameter :: len = 10, wid = 1, h = 0.1_dp, young = 1.2e6_dp, rho = 1
    type(mesh_t) :: mesh
    type(model_t) :: model
    type(assembly_t) :: asm
    type(linear_system_t) :: ls
    type(error_t), allocatable :: err
    type(newton_opts_t) :: opts
    type(newton_report_t) :: rep
    type(state_t) :: st
    type(scheme_t) :: nm
    real(dp) :: omega, period, w, wold, tcross(64), tc
    real(dp), allocatable :: zero(:)
    integer :: n, ncross, ntip, s
    integer, allocatable :: tip(:)

    omega = 1.8751_dp**2*sqrt(young*wid*h**3/12/(rho*wid*h*len**4))
    call mesh_plate(len, wid, 10, 1, mesh, err)
    call model_add_body(model, 'strip', mesh, young, 0._dp, rho, h)
    call model_finalize(model, err)
    do n = 1, model%nnode
      if (model%x0(1, n) < 1e-9_dp) model%fixed(dof(n, 1):dof(n, 6)) = .true.
    end do
    tip = pack([(n, n=1, model%nnode)], model%x0(1, :) > len - 1e-9_dp)
    ntip = size(tip)
    model%fext(dof(tip, 3)) = 1e-3_dp/ntip
    call assembly_setup(model, asm, err)
    allocate (st%q(model%ndof), st%qd(model%ndof), st%qdd(model%ndof), zero(model%ndof))
    call reference_state(model, st%q)
    opts%tol = 1e-12_dp
    call newton_solve(model, asm, ls, st%q, model%fext, opts, rep, err)
    st%qd = 0; st%qdd = 0; zero = 0
    nm = newmark_scheme(0.25_dp, 0.5_dp); nm%dt = 2*pi/omega/200
    ncross = 0
    wold = sum(st%q(dof(tip, 3)) - model%x0(3, tip))/ntip
    do s = 1, 800
      call newmark_step(model, asm, ls, nm, zero, opts, st, rep, err)
      if (allocated(err)) error stop 'newmark'
      w = sum(st%q(dof(tip, 3)) - model%x0(3, tip))/ntip
      if (sign(1._dp, w) /= sign(1._dp, wold) .and. ncross < size(tcross)) then
        tc = st%t - nm%dt*w/(w - wold)   ! linear interpolation of the crossing
        ncross = ncross + 1; tcross(ncross) = tc
      end if
      wold = w
    end do
    call ls%finish()
    period = 2*(tcross(ncross) - tcross(1))/(ncross - 1)   ! crossings are half a period apart
    if (is_root()) print '(a,i0,a,f10.6,a,f10.6)', 'zero crossings: ', ncross, &
      ', omega = ', 2*pi/period, ', Euler-Bernoulli: ', omega
    call check_close('free vibration: first frequency vs 1.8751^2 sqrt(EI/(rho A L^4))', &
                     2*pi/period, omega, 1e-2_dp)
  end subroutine free_vibration

  !> Steel sphere (R = 1, h = 0.05) translating at 10 m/s and spinning at 100 rad/s about an
  !> oblique axis, no load, trapezoidal rule, nsteps of dt.
  subroutine free_flight(dt, nsteps, dl, de, dpm, qout)
    real(dp), intent(in) :: dt
    integer, intent(in) :: nsteps
    real(dp), intent(out) :: dl, de, dpm
    real(dp), allocatable, intent(out), optional :: qout(:)
    type(mesh_t) :: mesh
    type(model_t) :: model
    type(assembly_t) :: asm
    type(linear_system_t) :: ls
    type(error_t), allocatable :: err
    type(newton_opts_t) :: opts
    type(newton_report_t) :: rep
    type(state_t) :: st
    type(scheme_t) :: nm
    type(balance_t) :: b0, b
    real(dp) :: v(3), w(3)
    real(dp), allocatable :: zero(:), q0(:)
    integer :: n, s

    call mesh_sphere(1._dp, 2, mesh, err)
    call model_add_body(model, 'sphere', mesh, 210e9_dp, 0.3_dp, 7700._dp, 0.05_dp)
    call model_finalize(model, err)
    call assembly_setup(model, asm, err)
    allocate (st%q(model%ndof), st%qd(model%ndof), st%qdd(model%ndof), zero(model%ndof))
    call reference_state(model, st%q)
    q0 = st%q; zero = 0; st%qdd = 0
    v = [10._dp, 0._dp, 0._dp]; w = 100*[0.3_dp, 0.5_dp, 0.8_dp]/norm2([0.3_dp, 0.5_dp, 0.8_dp])
    do n = 1, model%nnode
      st%qd(dof(n, 1):dof(n, 3)) = v + cross(w, model%x0(:, n))
      st%qd(dof(n, 4):dof(n, 6)) = cross(w, model%v0(:, n))
      st%qd(dof(n, 7)) = 0
    end do
    nm = newmark_scheme(0.25_dp, 0.5_dp); nm%dt = dt
    opts%tol = 1e-12_dp
    call account(model, asm, st, zero, q0, b0)
    dl = 0; de = 0; dpm = 0
    do s = 1, nsteps
      call newmark_step(model, asm, ls, nm, zero, opts, st, rep, err)
      if (allocated(err)) error stop 'newmark'
      call account(model, asm, st, zero, q0, b)
      dpm = max(dpm, norm2(b%p - b0%p)/norm2(b0%p))
      dl = max(dl, norm2(b%l - b0%l)/norm2(b0%l))
      de = max(de, abs(b%total - b0%total)/b0%total)
    end do
    call ls%finish()
    if (present(qout)) qout = st%q
  end subroutine free_flight

end program test_dynamics
