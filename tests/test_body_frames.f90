!> Kept factors on turned bodies (casca_body_frames): the two overlapping rings of the Schur
!> tests, K + cm M factorised where they stand, then both turned rigidly by 0.3 rad about
!> (1, 2, 3) with their contact rows made there. The Schur solve with the old factors must
!> solve the turned system [K' B'^T; C' 0] [x; dl] = [b; -gap] (K' assembled at the turned
!> rings): within 1e-10 once the frames follow the rings (the tangent of a turned body is
!> the turned tangent, so this holds exactly), and not within 1e-4 before (the test can
!> tell). The rotation found is the one applied, to 1e-12. And the same once the equations
!> have been numbered anew between two factorisations (ring 1 frozen, then woken).
program test_body_frames
  use casca_kinds, only: dp
  use casca_error, only: error_t
  use casca_model, only: model_t, dof
  use casca_assembly, only: assembly_t, assembly_setup, assemble
  use casca_linear_system, only: linear_system_t, rows_t, kkt_solve, follow_bodies
  use casca_mpi, only: mpi_start, mpi_stop
  use casca_test_rings, only: overlapping_rings, ring_rows, factorised, saddle_residuals
  use casca_check, only: check_le, check_true, check_summary
  implicit none

  type(model_t) :: model
  type(assembly_t) :: asm
  type(linear_system_t) :: ls, ls2
  logical, allocatable :: frozen(:)
  type(rows_t) :: rows, turned_rows
  type(error_t), allocatable :: err
  real(dp), allocatable :: q(:), qt(:), b(:)
  real(dp) :: turn(3, 3), axis(3), th, force, gap
  integer :: i, j

  call mpi_start()
  th = 0.3_dp
  axis = [1._dp, 2._dp, 3._dp]/sqrt(14._dp)
  do j = 1, 3   ! Rodrigues: cos I + sin [axis]x + (1 - cos) axis axis^T
    do i = 1, 3
      turn(i, j) = (1 - cos(th))*axis(i)*axis(j)
    end do
    turn(j, j) = turn(j, j) + cos(th)
  end do
  turn(1, 2) = turn(1, 2) - sin(th)*axis(3); turn(2, 1) = turn(2, 1) + sin(th)*axis(3)
  turn(1, 3) = turn(1, 3) + sin(th)*axis(2); turn(3, 1) = turn(3, 1) - sin(th)*axis(2)
  turn(2, 3) = turn(2, 3) - sin(th)*axis(1); turn(3, 2) = turn(3, 2) + sin(th)*axis(1)

  call overlapping_rings(model)
  call assembly_setup(model, asm, err, split=.true.)
  if (allocated(err)) error stop 'assembly'
  call ring_rows(model, asm, q, rows)
  call factorised(model, asm, q, rows, ls)
  call turned_system()
  call check_true('contact rows at the turned rings', size(turned_rows%gap) > 0)
  call solve_turned(ls, force, gap)
  write (*, '(a, es10.3)') 'frames not followed: force residual', force
  call check_true('frames not followed: the old factors do not solve the turned system (> 1e-4)', &
                  force > 1e-4_dp)
  call follow_bodies(ls, model, qt)
  call check_le('the rotation found, ring 1 (max entry difference)', &
                maxval(abs(ls%frames%rot(:, :, 1) - turn)), 1e-12_dp)
  call check_le('the rotation found, ring 2 (max entry difference)', &
                maxval(abs(ls%frames%rot(:, :, 2) - turn)), 1e-12_dp)
  call solve_turned(ls, force, gap)
  call check_le('frames followed: |K x + B^T dl - b| / max(|b|, |K x|, |B^T dl|)', force, 1e-10_dp)
  call check_le('frames followed: |C x + gap| / |gap|', gap, 1e-10_dp)
  call ls%finish()

  ! the same after the equations were numbered anew: first ring 1 frozen (advanced without
  ! solving), then both solved again, as when a body in free flight wakes
  allocate (frozen(model%ndof))
  frozen = .false.
  frozen(dof(model%body(1)%node_first, 1):dof(model%body(1)%node_last, 7)) = .true.
  call assembly_setup(model, asm, err, frozen, split=.true.)
  if (allocated(err)) error stop 'assembly, ring 1 frozen'
  call ring_rows(model, asm, q, rows)
  call factorised(model, asm, q, rows, ls2)
  call assembly_setup(model, asm, err, split=.true.)
  if (allocated(err)) error stop 'assembly, both solved'
  call ls2%new_pattern()
  call ring_rows(model, asm, q, rows)
  call factorised(model, asm, q, rows, ls2)
  call turned_system()
  call follow_bodies(ls2, model, qt)
  call solve_turned(ls2, force, gap)
  call check_le('equations numbered anew (ring 1 woken): |K x + B^T dl - b| / max(...)', force, 1e-10_dp)
  call check_le('equations numbered anew (ring 1 woken): |C x + gap| / |gap|', gap, 1e-10_dp)
  call ls2%finish()
  call check_summary()
  call mpi_stop()
contains

  !> the rings turned (qt), their rows there, K' assembled there (the factors stay K's) and a
  !> right-hand side b = [f; -gap]
  subroutine turned_system()
    real(dp), allocatable :: r(:)
    real(dp) :: energy
    integer :: i
    call ring_rows(model, asm, qt, turned_rows, turn)
    allocate (r(model%ndof))
    call assemble(model, asm, qt, .true., r, energy, 4e8_dp, qt)
    if (allocated(b)) deallocate (b)
    allocate (b(asm%neq + size(turned_rows%gap)))
    do i = 1, asm%neq
      b(i) = sin(0.37_dp*i)*1e3_dp
    end do
    b(asm%neq + 1:) = -turned_rows%gap
  end subroutine turned_system

  !> the Schur solve of the turned system with ls's factors, and its residuals
  subroutine solve_turned(lsys, force, gap)
    type(linear_system_t), intent(inout) :: lsys
    real(dp), intent(out) :: force, gap
    real(dp), allocatable :: x(:)
    type(error_t), allocatable :: e
    allocate (x(size(b)))
    call kkt_solve(lsys, asm, turned_rows, b, .false., x, e)
    if (allocated(e)) error stop 'solve'
    call saddle_residuals(asm, turned_rows, b, x, force, gap)
  end subroutine solve_turned
end program test_body_frames
