!> The Schur path's column cache and the choice of 'auto' (issue 18), on two rings that
!> overlap obliquely (several constraints) with the dynamic tangent K + cm M:
!>   - a solve whose rows were reordered, one dropped and one changed in value, with renew,
!>     keeps the other columns of Z and makes one: its increment equals that of a fresh Z
!>     (every column made again) to 1e-10 relative, and solves the saddle-point system
!>     [K C^T; C 0] [x; dl] = [b; -gap]: residuals, computed from K's entries and C's rows,
!>     within 1e-10 of the largest of the forces |b|, |K x|, |C^T dl| and of |gap|;
!>   - without renew the changed row keeps its column (none made) and the increment is that
!>     of the row's old values (fresh Z, residuals with the old row: 1e-10): one consistent,
!>     approximate system, like K's kept factors;
!>   - the same rows again keep every column (none made); the factors of K renewed make all;
!>   - choose_solver: a large set that stays (300 rows, one factorisation) goes to 'saddle'
!>     and stays there; a small set with a row changing at every iteration stays 'schur' and
!>     comes back to it from 'saddle'; K dealt to groups of ranks is always 'schur'.
program test_schur
  use casca_kinds, only: dp
  use casca_error, only: error_t
  use casca_model, only: model_t
  use casca_assembly, only: assembly_t, assembly_setup
  use casca_linear_system, only: linear_system_t, rows_t, factorise_blocks, kkt_solve
  use casca_solver_choice, only: solver_choice_t, choose_solver
  use casca_mpi, only: mpi_start, mpi_stop
  use casca_test_rings, only: overlapping_rings, ring_rows, factorised, saddle_residuals
  use casca_check, only: check_le, check_true, check_summary
  implicit none

  type(model_t) :: model
  type(assembly_t) :: asm
  type(linear_system_t) :: ls
  type(rows_t) :: ra, rb, rold
  type(error_t), allocatable :: err
  real(dp), allocatable :: q(:), b(:), x0(:), xs(:), xr(:), xf(:), xo(:)
  integer :: i, nb, kept, made

  call mpi_start()
  call overlapping_rings(model)
  call assembly_setup(model, asm, err)
  call ring_rows(model, asm, q, ra)
  call check_true('overlapping rings: at least 4 constraints', size(ra%gap) >= 4)
  call factorised(model, asm, q, ra, ls)

  ! a fresh Z for set A
  allocate (x0(asm%neq + size(ra%gap)))
  call kkt_solve(ls, asm, ra, rhs(ra), .false., x0, err)
  if (allocated(err)) error stop 'solve A'

  ! set B: A's rows reordered, the second dropped, the last changed in value (old: unchanged)
  nb = size(ra%gap) - 1
  rold = pick(ra, [(i, i=size(ra%gap), 3, -1), 1])
  rb = rold
  call change_row(rb, nb)
  b = rhs(rb)
  allocate (xs(asm%neq + nb), xr(asm%neq + nb), xf(asm%neq + nb), xo(asm%neq + nb))
  kept = ls%cache%kept; made = ls%cache%made
  call kkt_solve(ls, asm, rb, b, .false., xs, err)
  if (allocated(err)) error stop 'solve B, stale row kept'
  call check_true('set B: every row keeps its column (the changed one with its old values)', &
                  ls%cache%kept - kept == nb .and. ls%cache%made - made == 0)
  kept = ls%cache%kept; made = ls%cache%made
  call kkt_solve(ls, asm, rb, b, .true., xr, err)
  if (allocated(err)) error stop 'solve B, renewed'
  call check_true('set B renewed: the unchanged rows keep their columns, the changed one is made', &
                  ls%cache%kept - kept == nb - 1 .and. ls%cache%made - made == 1)
  ls%cache%current = .false.   ! every column made again
  call kkt_solve(ls, asm, rb, b, .false., xf, err)
  if (allocated(err)) error stop 'solve B, fresh'
  call check_le('increment with kept columns vs a fresh Z (max diff / max |x|)', &
                maxval(abs(xr - xf))/maxval(abs(xf)), 1e-10_dp)
  call check_le('dlambda with kept columns vs a fresh Z (max diff / max |dl|)', &
                maxval(abs(xr(asm%neq + 1:) - xf(asm%neq + 1:)))/maxval(abs(xf(asm%neq + 1:))), 1e-10_dp)
  call residuals('set B, kept columns', rb, b, xr)
  ls%cache%current = .false.
  call kkt_solve(ls, asm, rold, b, .false., xo, err)
  if (allocated(err)) error stop 'solve B with the old row, fresh'
  call check_le('stale row kept: the increment of a fresh Z for the old row (max diff / max |x|)', &
                maxval(abs(xs - xo))/maxval(abs(xo)), 1e-10_dp)
  call residuals('stale row kept, with the old row', rold, b, xs)
  call check_true('the changed row changes the increment (the test can tell: > 1e-6 relative)', &
                  maxval(abs(xs - xf))/maxval(abs(xf)) > 1e-6_dp)
  call kkt_solve(ls, asm, rb, b, .true., xr, err)   ! the cache back to set B

  kept = ls%cache%kept; made = ls%cache%made
  call kkt_solve(ls, asm, rb, b, .false., xr, err)
  call check_true('the same rows again: every column kept, none made', &
                  ls%cache%made == made .and. ls%cache%kept == kept)
  call factorise_blocks(ls, model, asm, rb, q, err)
  call kkt_solve(ls, asm, rb, b, .false., xr, err)
  call check_true('K factorised again: every column made', ls%cache%made - made == nb)
  call ls%finish()

  call choices()
  call check_summary()
  call mpi_stop()
contains

  !> the right-hand side: arbitrary smooth forces, then -gap
  function rhs(rows) result(bb)
    type(rows_t), intent(in) :: rows
    real(dp), allocatable :: bb(:)
    integer :: k
    bb = [([(1e3_dp*sin(0.37_dp*k), k=1, asm%neq)]), -rows%gap]
  end function rhs

  !> the rows picked, in that order (entries in row order, each row ending with its diagonal)
  function pick(rows, which) result(p)
    type(rows_t), intent(in) :: rows
    integer, intent(in) :: which(:)
    type(rows_t) :: p
    integer :: k
    logical, allocatable :: take(:)
    allocate (p%irn(0), p%jcn(0), p%val(0), p%fval(0))
    do k = 1, size(which)
      take = rows%irn == asm%neq + which(k)
      p%irn = [p%irn, pack(0*rows%irn + asm%neq + k, take)]
      p%jcn = [p%jcn, pack(rows%jcn, take .and. rows%jcn <= asm%neq), asm%neq + k]
      p%val = [p%val, pack(rows%val, take)]
      p%fval = [p%fval, pack(rows%fval, take)]
    end do
    p%key = rows%key(:, which)
    p%gap = rows%gap(which)
  end function pick

  !> row k's values tilted (its normal turned a little), key and pattern kept
  subroutine change_row(rows, k)
    type(rows_t), intent(inout) :: rows
    integer, intent(in) :: k
    integer :: e, n
    n = 0
    do e = 1, size(rows%irn)
      if (rows%irn(e) /= asm%neq + k .or. rows%jcn(e) == rows%irn(e)) cycle
      n = n + 1
      rows%val(e) = rows%val(e)*(1 + 0.05_dp*sin(real(n, dp)))
    end do
    rows%fval = rows%val
  end subroutine change_row

  !> the saddle-point residuals of x (casca_test_rings), each within 1e-10
  subroutine residuals(what, rows, bb, x)
    character(len=*), intent(in) :: what
    type(rows_t), intent(in) :: rows
    real(dp), intent(in) :: bb(:), x(:)
    real(dp) :: force, gap
    call saddle_residuals(asm, rows, bb, x, force, gap)
    call check_le(what//': residual |K x + C^T dl - b| / max(|b|, |K x|, |C^T dl|)', force, 1e-10_dp)
    call check_le(what//': residual |C x + gap| / |gap|', gap, 1e-10_dp)
  end subroutine residuals

  !> choose_solver on synthetic rows (row k: one entry on equation k, then its diagonal)
  subroutine choices()
    type(solver_choice_t) :: ch, ch2
    logical :: schur, stayed
    integer :: it
    schur = .true.
    stayed = .true.
    do it = 1, 40   ! 300 rows that stay; K factorised once
      call choose_from(ch, 300, 0, it == 2, .true., schur)
      if (it > 1) stayed = stayed .and. .not. schur
    end do
    call check_true('auto: 300 constraints that stay go to saddle at once and stay there', stayed)
    schur = .true.
    stayed = .true.
    do it = 1, 40   ! 5 rows, one of them new at every iteration
      call choose_from(ch2, 5, it, .false., .true., schur)
      stayed = stayed .and. schur
    end do
    call check_true('auto: 5 constraints, one changing at every iteration, stay schur', stayed)
    schur = .false.
    do it = 1, 40
      call choose_from(ch2, 5, 100 + it, .false., .true., schur)
    end do
    call check_true('auto: ... and come back to schur from saddle', schur)
    ch2 = solver_choice_t()
    schur = .true.
    do it = 1, 40
      call choose_from(ch2, 300, 0, .false., .false., schur)
    end do
    call check_true('auto: K dealt to groups of ranks: always schur', schur)
  end subroutine choices

  !> one choice with n synthetic rows whose last one has key shift (a new row when it changes)
  subroutine choose_from(ch, n, shift, refactored, can_saddle, schur)
    type(solver_choice_t), intent(inout) :: ch
    integer, intent(in) :: n, shift
    logical, intent(in) :: refactored, can_saddle
    logical, intent(inout) :: schur
    integer :: irn(2*n), jcn(2*n), key(2, n), k
    real(dp) :: val(2*n)
    do k = 1, n
      irn(2*k - 1:2*k) = 1000 + k
      jcn(2*k - 1:2*k) = [k + merge(shift, 0, k == n), 1000 + k]
      val(2*k - 1:2*k) = [1._dp, 0._dp]
      key(:, k) = [4*k, merge(shift, 0, k == n)]
    end do
    call choose_solver(ch, irn, jcn, val, val, key, refactored, can_saddle, schur)
  end subroutine choose_from
end program test_schur
