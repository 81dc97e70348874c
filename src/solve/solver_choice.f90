!> &contact solver = 'auto': the Schur complement of K or the whole saddle-point matrix,
!> chosen at every Newton iteration from what each would have to redo (docs/performance.md):
!>  - 'schur' solves K for one column of Z per new constraint row (a new key), and for all
!>    nc columns after each factorisation of K;
!>  - 'saddle' analyses and factorises the saddle-point matrix again whenever the constraint
!>    pattern changes, which costs about as much as c_analysis columns of Z.
!> Both needs are followed as running means per iteration (whichever path is in use) and
!> the other path is taken when it is cheaper by a margin and its saving pays for the switch
!> within a horizon of iterations. The figures are replicated, so every rank chooses alike.
module casca_solver_choice
  use casca_kinds, only: dp
  use casca_schur, only: match_rows
  implicit none
  private
  public :: solver_choice_t, choose_solver

  !> a saddle-point analysis and factorisation, in Z columns: 163 on a plate of 256 nodes,
  !> 85 on one of 961 (docs/performance.md)
  real(dp), parameter :: c_analysis = 160
  real(dp), parameter :: weight = 0.05_dp      !< of the last iteration in the running means
  real(dp), parameter :: horizon = 20          !< iterations a switch must pay for itself in
  real(dp), parameter :: margin = 1.5_dp       !< and by how much the other path must be cheaper

  type :: solver_choice_t
    real(dp) :: columns = 0          !< Z columns the Schur path needs per iteration (mean)
    real(dp) :: changes = 0          !< constraint-pattern changes per iteration (mean)
    integer, allocatable :: irn(:), jcn(:), key(:, :)   !< the rows of the last iteration
    real(dp), allocatable :: val(:), fval(:)
  end type solver_choice_t

contains

  !> Update the running means with this iteration's rows (refactored: K was factorised in
  !> the last iteration) and choose: schur on entry is the path in use, on exit the one to
  !> take. can_saddle: K is one block (not dealt to groups of ranks).
  subroutine choose_solver(ch, irn, jcn, val, fval, key, refactored, can_saddle, schur)
    type(solver_choice_t), intent(inout) :: ch
    integer, intent(in) :: irn(:), jcn(:), key(:, :)
    real(dp), intent(in) :: val(:), fval(:)
    logical, intent(in) :: refactored, can_saddle
    logical, intent(inout) :: schur
    integer, allocatable :: col(:)
    logical, allocatable :: same(:), exact(:)
    integer :: nc
    logical :: changed
    nc = size(key, 2)
    allocate (col(nc), same(nc), exact(nc))
    same = .false.
    changed = .true.
    if (allocated(ch%key)) then
      call match_rows(ch%irn, ch%jcn, ch%val, ch%fval, ch%key, irn, jcn, val, fval, key, col, same, exact)
      if (size(ch%irn) == size(irn)) changed = any(ch%irn /= irn) .or. any(ch%jcn /= jcn)
    end if
    ch%columns = (1 - weight)*ch%columns + weight*merge(nc, count(.not. same), refactored)
    ch%changes = (1 - weight)*ch%changes + weight*merge(1, 0, changed .and. nc > 0)
    ch%irn = irn; ch%jcn = jcn; ch%val = val; ch%fval = fval; ch%key = key
    if (.not. can_saddle) then
      schur = .true.
    else if (schur) then
      schur = .not. (ch%columns > margin*ch%changes*c_analysis + c_analysis/horizon)
    else
      schur = ch%changes*c_analysis > margin*ch%columns + nc/horizon
    end if
  end subroutine choose_solver
end module casca_solver_choice
