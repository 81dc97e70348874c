!> Benchmark: element kernel (force + Hessian) time per element, and the parts of one Newton
!> iteration (assembly, factorisation, solution) on a closed sphere. Prints figures only.
!> Usage: bench_solver [n_div [ordering]]  (n_div = 6: 720 elements, 22,694 unknowns;
!> ordering: MUMPS ICNTL(7), 7 = automatic, 0 AMD, 2 AMF, 4 PORD, 6 QAMD)
program bench_solver
  use casca_kinds, only: dp
  use casca_error, only: error_t
  use casca_mesh, only: mesh_t
  use casca_mesh_generators, only: mesh_sphere
  use casca_model, only: model_t, model_add_body, model_finalize, reference_state
  use casca_assembly, only: assembly_t, assembly_setup, assemble
  use casca_shell_element, only: shell_energy_force
  use casca_mumps_solver, only: sparse_solver_t
  use casca_metis, only: nested_dissection
  use casca_mpi, only: mpi_start, mpi_stop, is_root, n_ranks, wall_time
  implicit none

  type(mesh_t) :: mesh
  type(model_t) :: model
  type(assembly_t) :: asm
  type(sparse_solver_t) :: solver
  type(error_t), allocatable :: err
  real(dp), allocatable :: q(:), r(:), qs(:), b(:, :), x(:, :)
  real(dp) :: qe(7, 10), fe(70), ke(70, 70), u, t0, t_el, t_as, t_fa, t_so, t_an, flops, t_f
  real(dp) :: gemm_rate
  real(dp), allocatable :: ga(:, :), gb(:, :), gc(:, :)
  integer :: ndiv, i, e, nrep, nel
  integer, allocatable :: perm(:)
  character(len=16) :: arg

  call mpi_start()
  ndiv = 6
  if (command_argument_count() >= 1) then
    call get_command_argument(1, arg); read (arg, *) ndiv
  end if
  if (command_argument_count() >= 2) then   ! MUMPS ICNTL(7) ordering
    call get_command_argument(2, arg); read (arg, *) solver%ordering
  end if
  call mesh_sphere(1._dp, ndiv, mesh, err)
  call model_add_body(model, 'sphere', mesh, 210e9_dp, 0.3_dp, 7700._dp, 0.05_dp)
  call model_finalize(model, err)
  allocate (q(model%ndof), r(model%ndof))
  call reference_state(model, q)
  q = q*(1 + 1e-3_dp)   ! a strained state

  ! kernel alone, on one rank's worth of repetitions
  nel = min(model%nelem, 200); nrep = 5
  t0 = wall_time()
  do i = 1, nrep
    do e = 1, nel
      call gather(e, qe)
      call shell_energy_force(model%rule, 0.05_dp, model%body(1)%lam, model%body(1)%mu, &
                              model%binv(:, :, :, e), model%wdet(:, e), qe, .true., u, fe, ke)
    end do
  end do
  t_el = (wall_time() - t0)/(nrep*nel)
  t0 = wall_time()
  do i = 1, nrep
    do e = 1, nel
      call gather(e, qe)
      call shell_energy_force(model%rule, 0.05_dp, model%body(1)%lam, model%body(1)%mu, &
                              model%binv(:, :, :, e), model%wdet(:, e), qe, .false., u, fe, ke)
    end do
  end do
  t_f = (wall_time() - t0)/(nrep*nel)
  ! the machine's DGEMM rate (BLAS in use), the yardstick for the kernel's rate
  allocate (ga(1000, 1000), gb(1000, 1000), gc(1000, 1000))
  call random_number(ga); call random_number(gb)
  t0 = wall_time()
  call dgemm('N', 'N', 1000, 1000, 1000, 1._dp, ga, 1000, gb, 1000, 0._dp, gc, 1000)
  gemm_rate = 2e9_dp/(wall_time() - t0)*1e-9
  ! flops per element, counted from the kernel's loops (multiply-adds counted as 2)
  flops = model%rule%np*(20*9*20*9._dp + 10*(20*3*3*2 + 27*10) + 55*60._dp + 3000)

  call assembly_setup(model, asm, err)
  t0 = wall_time()
  allocate (perm(asm%neq))
  if (solver%ordering == 1) call nested_dissection(model%conn, model%nnode, asm%eq, asm%neq, perm, err)
  call solver%analyse(asm%neq, asm%irn, asm%jcn, perm, err)
  t_an = wall_time() - t0
  qs = 0*q
  allocate (b(asm%neq, 1), x(asm%neq, 1))
  t_as = 0; t_fa = 0; t_so = 0
  nrep = 3
  do i = 1, nrep
    t0 = wall_time()
    call assemble(model, asm, q, .true., r, u, 1e8_dp, qs)
    t_as = t_as + wall_time() - t0
    t0 = wall_time()
    call solver%factorise(asm%a, err)
    if (allocated(err)) error stop 'factorise'
    t_fa = t_fa + wall_time() - t0
    b = 1
    t0 = wall_time()
    call solver%solve(b, x, err)
    t_so = t_so + wall_time() - t0
  end do
  if (is_root()) then
    print '(a,i0,a,i0,a,i0,a,i0)', 'sphere n_div=', ndiv, ': elements ', model%nelem, &
      ', nodes ', model%nnode, ', unknowns ', asm%neq
    print '(a,i0)', 'ranks: ', n_ranks
    print '(a,f8.4,a,f6.2,a,f5.1,a)', 'element force+Hessian: ', 1e3*t_el, ' ms/element  (', &
      flops/t_el*1e-9, ' GFlop/s, ', 100*flops/t_el*1e-9/gemm_rate, '% of DGEMM)'
    print '(a,f8.4,a)', 'element force only:    ', 1e3*t_f, ' ms/element'
    print '(a,f8.2,a)', 'DGEMM 1000x1000:       ', gemm_rate, ' GFlop/s (this machine, this BLAS)'
    print '(a,f8.4,a)', 'analysis (once):       ', t_an, ' s'
    print '(a,f8.4,a)', 'assembly / iteration:  ', t_as/nrep, ' s'
    print '(a,f8.4,a)', 'factorisation / iter.: ', t_fa/nrep, ' s'
    print '(a,f8.4,a)', 'solution / iteration:  ', t_so/nrep, ' s'
    print '(a,f8.4,a)', 'Newton iteration:      ', (t_as + t_fa + t_so)/nrep, ' s'
  end if
  call solver%finish()
  call mpi_stop()
contains
  subroutine gather(ee, qq)
    integer, intent(in) :: ee
    real(dp), intent(out) :: qq(7, 10)
    integer :: l
    do l = 1, 10
      qq(:, l) = q(7*(model%conn(l, ee) - 1) + 1:7*model%conn(l, ee))
    end do
  end subroutine gather
end program bench_solver
