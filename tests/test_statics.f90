!> Statics of plate strips against analytic and published answers: linear cantilever, plate
!> strip in cylindrical bending with and without the thickness parameter, the large-deflection
!> cantilever of Sze, Liu & Lo (2004), and the convergence rate of Newton.
program test_statics
  use casca_kinds, only: dp
  use casca_error, only: error_t
  use casca_mesh, only: mesh_t
  use casca_mesh_generators, only: mesh_plate
  use casca_model, only: model_t, model_add_body, model_finalize, dof, reference_state
  use casca_assembly, only: assembly_t, assembly_setup
  use casca_linear_system, only: linear_system_t
  use casca_newton, only: newton_opts_t, newton_report_t, newton_solve
  use casca_mpi, only: mpi_start, mpi_stop
  use casca_check, only: check_le, check_close, check_true, check_summary
  implicit none

  real(dp), parameter :: len = 10, wid = 1, thick = 0.1_dp, young = 1.2e6_dp
  ! Sze, Liu & Lo (2004), cantilever under end shear: tip deflection and shortening
  real(dp), parameter :: sze_w(10) = [1.309_dp, 2.493_dp, 3.488_dp, 4.292_dp, 4.933_dp, &
                                      5.444_dp, 5.855_dp, 6.190_dp, 6.467_dp, 6.698_dp]
  real(dp), parameter :: sze_u(10) = [0.103_dp, 0.381_dp, 0.763_dp, 1.184_dp, 1.604_dp, &
                                      2.002_dp, 2.370_dp, 2.705_dp, 3.010_dp, 3.286_dp]
  integer, parameter :: nx = 10, ny = 1
  real(dp) :: w, u, w_free, w_frozen, d_plate, rate
  real(dp) :: wl(10), ul(10)
  type(newton_report_t) :: rep
  integer :: i, k
  character(len=64) :: label

  call mpi_start()

  ! linear cantilever, nu = 0: P L^3 / (3 E I)
  call cantilever(0._dp, 1e-4_dp, 1, .false., .false., w, u, rep)
  call check_close('linear cantilever: tip deflection vs P L^3/(3EI)', w, &
                   1e-4_dp*len**3/(3*young*wid*thick**3/12), 1e-2_dp)

  ! cylindrical bending (plane strain across the width), nu = 0.3
  call cantilever(0.3_dp, 1e-4_dp, 1, .true., .false., w_free, u, rep)
  d_plate = young*thick**3/(12*(1 - 0.3_dp**2))
  call check_close('cylindrical bending, a free: deflection vs P L^3/(3 D b)', w_free, &
                   1e-4_dp*len**3/(3*d_plate*wid), 1e-2_dp)
  call cantilever(0.3_dp, 1e-4_dp, 1, .true., .true., w_frozen, u, rep)
  call check_close('cylindrical bending: stiffening with a frozen vs (1-nu)^2/(1-2nu)', &
                   w_free/w_frozen, (1 - 0.3_dp)**2/(1 - 2*0.3_dp), 1e-2_dp)

  ! large deflection, ten load levels
  call cantilever(0._dp, 4._dp, 10, .false., .false., w, u, rep, wl, ul)
  do i = 1, 10
    write (label, '(a,f3.1,a)') 'Sze cantilever P = ', 0.4_dp*i, ': W'
    call check_close(trim(label), wl(i), sze_w(i), 1e-2_dp)
    write (label, '(a,f3.1,a)') 'Sze cantilever P = ', 0.4_dp*i, ': -U'
    call check_close(trim(label), ul(i), sze_u(i), 1e-2_dp)
  end do

  ! Newton: observed order from the last three increments above round-off, first load step
  call cantilever(0._dp, 0.4_dp, 1, .false., .false., w, u, rep)
  k = rep%iters
  do while (k > 3 .and. rep%incr(k) < 1e-13_dp)
    k = k - 1
  end do
  rate = log(rep%incr(k)/rep%incr(k - 1))/log(rep%incr(k - 1)/rep%incr(k - 2))
  print '(a,*(es9.2,1x))', 'Newton increments: ', rep%incr(1:rep%iters)
  call check_le('Newton converges quadratically: 1.8 - observed order', 1.8_dp - rate, 0._dp)

  call check_summary()
  call mpi_stop()

contains

  !> Cantilever strip clamped at x = 0 (Y and G fixed), end load p in +z in nlev equal
  !> steps; tip deflection and shortening at each level. plane: y and fibre-y fixed
  !> everywhere (cylindrical bending); frozen: thickness parameter fixed at 0.
  subroutine cantilever(nu, p, nlev, plane, frozen, wtip, utip, rep, wlev, ulev)
    real(dp), intent(in) :: nu, p
    integer, intent(in) :: nlev
    logical, intent(in) :: plane, frozen
    real(dp), intent(out) :: wtip, utip
    type(newton_report_t), intent(out) :: rep
    real(dp), intent(out), optional :: wlev(:), ulev(:)
    type(mesh_t) :: mesh
    type(model_t) :: model
    type(assembly_t) :: asm
    type(linear_system_t) :: ls
    type(error_t), allocatable :: err
    type(newton_opts_t) :: opts
    real(dp), allocatable :: q(:), f(:)
    integer :: n, j, lev, ntip
    real(dp) :: y

    call mesh_plate(len, wid, nx, ny, mesh, err)
    call model_add_body(model, 'strip', mesh, young, nu, 1._dp, thick)
    call model_finalize(model, err)
    if (allocated(err)) error stop 'model'
    ntip = 0
    do n = 1, model%nnode
      if (model%x0(1, n) < 1e-9_dp) model%fixed(dof(n, 1):dof(n, 6)) = .true.
      if (plane) model%fixed([dof(n, 2), dof(n, 5)]) = .true.
      if (frozen) model%fixed(dof(n, 7)) = .true.
      if (model%x0(1, n) > len - 1e-9_dp) then
        ! consistent load of a cubic edge: 1/8, 3/8, 3/8, 1/8 of each segment's share
        y = model%x0(2, n)/(wid/(3*ny))
        j = nint(y)
        if (mod(j, 3) /= 0) then
          model%fext(dof(n, 3)) = 3*p/(8*ny)
        else if (j == 0 .or. j == 3*ny) then
          model%fext(dof(n, 3)) = p/(8*ny)
        else
          model%fext(dof(n, 3)) = 2*p/(8*ny)
        end if
        ntip = ntip + 1
      end if
    end do
    call assembly_setup(model, asm, err)
    allocate (q(model%ndof))
    call reference_state(model, q)
    opts%tol = 1e-14_dp; opts%max_iter = 30
    opts%reuse = .false.   ! full Newton: the rate test measures its order
    f = model%fext
    do lev = 1, nlev
      call newton_solve(model, asm, ls, q, f*(real(lev, dp)/nlev), opts, rep, err)
      if (allocated(err)) error stop 'newton'
      wtip = 0; utip = 0
      do n = 1, model%nnode
        if (model%x0(1, n) > len - 1e-9_dp) then
          wtip = wtip + (q(dof(n, 3)) - model%x0(3, n))/ntip
          utip = utip - (q(dof(n, 1)) - model%x0(1, n))/ntip
        end if
      end do
      if (present(wlev)) then
        wlev(lev) = wtip; ulev(lev) = utip
      end if
    end do
    call ls%finish()
  end subroutine cantilever
end program test_statics
