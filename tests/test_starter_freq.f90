!> The starter's estimate of a shell mesh's highest frequency (src/scene/starter.f90) against the
!> eigenvalues of the element: a free flat steel plate 0.4 x 0.4 m, K and M assembled by
!> casca_assembly at the reference state (M as the difference of K + M and K), the massless
!> thickness parameters condensed out, omega_max^2 the largest eigenvalue of L^-1 K L^-T
!> (M = L L^T). Asserted: omega_max within 15% of the fibre-stretch estimate
!> 2 sqrt(3) c_d / h (measured: 1.08 to 1.12 times it) for h = 10 mm and 2 mm on 2 x 2 cells, and
!> for h = 10 mm on 4 x 4 cells (the mode is through the thickness: the mesh does not move
!> it), and above the membrane estimate 2 c / l_min there.
program test_starter_freq
  use casca_kinds, only: dp
  use casca_error, only: error_t
  use casca_mesh, only: mesh_t
  use casca_mesh_generators, only: mesh_plate
  use casca_model, only: model_t, model_add_body, model_finalize, reference_state
  use casca_assembly, only: assembly_t, assembly_setup, assemble
  use casca_lapack, only: dsyev, dpotrf, dpotrs
  use casca_starter, only: thickness_frequency
  use casca_mpi, only: mpi_start, mpi_stop
  use casca_check, only: check_close, check_true, check_summary
  implicit none

  real(dp), parameter :: young = 210e9_dp, nu = 0.3_dp, rho = 7800, side = 0.4_dp
  real(dp) :: omega, estimate, membrane
  character(len=80) :: label
  integer :: k
  real(dp), parameter :: hs(3) = [0.01_dp, 0.002_dp, 0.01_dp]
  integer, parameter :: cells(3) = [2, 2, 4]

  call mpi_start()
  do k = 1, 3
    call highest_frequency(hs(k), cells(k), omega, estimate)
    write (label, '(a,f5.3,a,i0,a,i0,a)') 'free plate, h ', hs(k), ' m, ', cells(k), ' x ', &
      cells(k), ' cells: omega_max vs 2 sqrt(3) c_d / h'
    call check_close(trim(label), omega, estimate, 0.15_dp)
  end do
  membrane = 2*sqrt(young/(rho*(1 - nu**2)))/(side/cells(3))
  call check_true('4 x 4 cells, h 10 mm: omega_max above the membrane estimate 2 c / l_min', &
                  omega > membrane)
  call check_summary()
  call mpi_stop()

contains

  !> omega_max of the free plate of thickness h on n x n cells, and the starter's estimate
  subroutine highest_frequency(h, n, omega_max, omega_t)
    real(dp), intent(in) :: h
    integer, intent(in) :: n
    real(dp), intent(out) :: omega_max, omega_t
    type(mesh_t) :: mesh
    type(model_t) :: model
    type(assembly_t) :: asm
    type(error_t), allocatable :: err
    real(dp), allocatable :: q(:), r(:), kd(:, :), md(:, :), t(:, :), kr(:, :), w(:), work(:)
    integer, allocatable :: ia(:), iv(:)
    real(dp) :: energy
    integer :: i, info, na, nv
    call mesh_plate(side, side, n, n, mesh, err)
    call model_add_body(model, 'plate', mesh, young, nu, rho, h)
    call model_finalize(model, err)
    call assembly_setup(model, asm, err)
    allocate (q(model%ndof), r(model%ndof))
    call reference_state(model, q)
    call assemble(model, asm, q, .true., r, energy)
    kd = dense(asm)
    call assemble(model, asm, q, .true., r, energy, cm=1._dp, qs=q)
    md = dense(asm) - kd
    ! the thickness parameters (every 7th) carry no mass: condense them
    ia = [(asm%eq(7*i), i=1, model%nnode)]
    iv = pack([(i, i=1, asm%neq)], [(all(ia /= i), i=1, asm%neq)])
    na = size(ia); nv = size(iv)
    t = kd(ia, iv)
    kr = kd(ia, ia)
    call dpotrf('L', na, kr, na, info)
    call dpotrs('L', na, nv, kr, na, t, na, info)
    kr = kd(iv, iv) - matmul(kd(iv, ia), t)
    md = md(iv, iv)
    call dpotrf('L', nv, md, nv, info)
    kr = transpose(lower_solve(md, transpose(lower_solve(md, kr))))   ! L^-1 K L^-T
    allocate (w(nv), work(66*nv))
    call dsyev('N', 'U', nv, kr, nv, w, work, size(work), info)
    omega_max = sqrt(maxval(w))
    omega_t = thickness_frequency(model%body(1)%lam, model%body(1)%mu, rho, h)
  end subroutine highest_frequency

  !> The assembled lower triangle (one rank, one block) as a full symmetric matrix
  function dense(asm) result(a)
    type(assembly_t), intent(in) :: asm
    real(dp), allocatable :: a(:, :)
    integer :: p
    allocate (a(asm%neq, asm%neq))
    a = 0
    do p = 1, size(asm%a)
      a(asm%irn(p), asm%jcn(p)) = a(asm%irn(p), asm%jcn(p)) + asm%a(p)
      if (asm%irn(p) /= asm%jcn(p)) a(asm%jcn(p), asm%irn(p)) = a(asm%jcn(p), asm%irn(p)) + asm%a(p)
    end do
  end function dense

  !> L^-1 b by forward substitution, L the lower triangle of l
  function lower_solve(l, b) result(x)
    real(dp), intent(in) :: l(:, :), b(:, :)
    real(dp) :: x(size(b, 1), size(b, 2))
    integer :: i
    do i = 1, size(b, 1)
      x(i, :) = (b(i, :) - matmul(l(i, 1:i - 1), x(1:i - 1, :)))/l(i, i)
    end do
  end function lower_solve
end program test_starter_freq
