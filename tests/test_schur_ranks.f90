!> The Schur path with K dealt to groups of ranks (run on 2 ranks: one ring each, every rank
!> holding only its own equations' entries of a row; on 1 rank: one block), on two rings
!> that overlap obliquely, with force columns B that differ from the constraint rows C on
!> ring 1's equations only, as generalized-alpha's force point makes them (B's entries
!> there scaled by 1 + 0.02 sin e):
!>   - the increment solves [K B^T; C 0] [x; dl] = [b; -gap]: |K x + B^T dl - b| within 1e-10
!>     of max(|b|, |K x|, |B^T dl|) on every rank's equations, and |C x + gap| within 1e-10
!>     of |gap| (C x summed over the ranks);
!>   - the rows do differ (B /= C somewhere), and on 2 ranks ring 2's rank sees B = C in its
!>     own entries: the case where a rank-local test of the symmetry of S = C K^-1 B^T gave
!>     that rank other multipliers (two balls glancing on 2 ranks kept the momentum to
!>     2.7e-9 instead of 6e-14).
program test_schur_ranks
  use casca_kinds, only: dp
  use casca_error, only: error_t
  use casca_model, only: model_t
  use casca_assembly, only: assembly_t, assembly_setup
  use casca_linear_system, only: linear_system_t, rows_t, kkt_solve
  use casca_mpi, only: mpi_start, mpi_stop, my_rank, n_ranks, sum_all
  use casca_test_rings, only: overlapping_rings, ring_rows, factorised, saddle_residuals
  use casca_check, only: check_le, check_true, check_summary
  implicit none

  type(model_t) :: model
  type(assembly_t) :: asm
  type(linear_system_t) :: ls
  type(rows_t) :: rows
  type(error_t), allocatable :: err
  real(dp), allocatable :: q(:), b(:), x(:)
  real(dp) :: force, gap
  integer, allocatable :: body_of(:)
  integer :: i, e, k, n, nc, differ
  real(dp) :: differ_here(2)   !< entries B /= C seen by rank 0, by the others

  call mpi_start()
  call overlapping_rings(model)
  call assembly_setup(model, asm, err, split=.true.)
  if (allocated(err)) error stop 'assembly'
  call check_true('the rings are dealt one to a rank (2 ranks) or kept in one block (1 rank)', &
                  asm%ngroups == n_ranks)
  call ring_rows(model, asm, q, rows)
  n = asm%neq; nc = size(rows%gap)
  call check_true('overlapping rings: at least 4 constraints', nc >= 4)

  ! B /= C on ring 1's equations only
  allocate (body_of(n))
  do i = 1, model%ndof
    if (asm%eq(i) > 0) body_of(asm%eq(i)) = model%node_body((i - 1)/7 + 1)
  end do
  differ_here = 0
  do e = 1, size(rows%irn)
    if (rows%irn(e) == rows%jcn(e)) cycle
    if (body_of(rows%jcn(e)) == 1) rows%fval(e) = rows%val(e)*(1 + 0.02_dp*sin(real(e, dp)))
  end do
  differ = count(rows%fval /= rows%val)
  differ_here(min(my_rank, 1) + 1) = real(differ, dp)
  call sum_all(differ); call sum_all(differ_here)
  call check_true('B differs from C in some entries', differ > 0)
  if (n_ranks == 2) call check_true("2 ranks: ring 2's rank sees B = C in its own entries", &
                                    differ_here(1) > 0 .and. differ_here(2) == 0)

  call factorised(model, asm, q, rows, ls)
  b = [([(1e3_dp*sin(0.37_dp*(k + 7*my_rank)), k=1, n)]), -rows%gap]
  allocate (x(n + nc))
  call kkt_solve(ls, asm, rows, b, .false., x, err)
  if (allocated(err)) error stop 'solve'

  call saddle_residuals(asm, rows, b, x, force, gap)
  call check_le('|K x + B^T dl - b| / max(|b|, |K x|, |B^T dl|), the largest over the ranks', &
                force, 1e-10_dp)
  call check_le('|C x + gap| / |gap|', gap, 1e-10_dp)
  call ls%finish()
  call check_summary()
  call mpi_stop()
end program test_schur_ranks
