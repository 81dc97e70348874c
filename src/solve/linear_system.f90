!> The linear algebra of one Newton iteration: the tangent K in diagonal blocks (one MUMPS
!> instance each, casca_assembly), the constraint rows C, and the saddle-point system
!>     [ K  C^T ] [ dq      ]   [ b ]
!>     [ C  0   ] [ dlambda ] = [ c ]
!> solved either through the Schur complement of K ('schur': K's pattern never changes; the
!> cache of casca_schur keeps each column of Z = K^-1 C^T, and S = C Z, while its row and
!> K's factors stay)
!> or by factorising the whole matrix ('saddle': one block, re-analysed whenever the
!> constraint pattern changes).
module casca_linear_system
  use casca_kinds, only: dp
  use casca_error, only: error_t
  use casca_model, only: model_t
  use casca_assembly, only: assembly_t, nblocks
  use casca_mumps_solver, only: sparse_solver_t
  use casca_schur, only: schur_t, schur_match, schur_store, schur_apply
  use casca_solver_choice, only: solver_choice_t, choose_solver
  use casca_mass_solver, only: mass_solver_t
  use casca_contact_correction, only: correction_cache_t
  use casca_metis, only: nested_dissection
  use casca_body_frames, only: body_frames_t, frames_keep, frames_follow, frames_turn
  use casca_mpi, only: sum_all, share_error
  implicit none
  private
  public :: linear_system_t, rows_t, analyse_blocks, factorise_blocks, solve_blocks, kkt_solve, &
            negative_pivots, follow_bodies

  !> Constraint rows in MUMPS's coordinates: entries (neq + k, eq) of dg_k/dq, a zero
  !> diagonal (neq + k, neq + k) per multiplier, and the gaps; key(2, k): the (node, element)
  !> of constraint k, which identifies its row while the point is held
  !> fval: the columns through which the multipliers act (C^T, but for sliding friction
  !> (C_n - mu_d C_s)^T: its force follows |lambda|), same entries as val; the Schur path
  !> uses them (S = C K^-1 B^T, unsymmetric), the saddle path does not (MUMPS's matrix is
  !> symmetric there: sliding converges by fixed point)
  type :: rows_t
    integer, allocatable :: irn(:), jcn(:), key(:, :)
    real(dp), allocatable :: val(:), gap(:), fval(:)
  end type rows_t

  type :: linear_system_t
    type(sparse_solver_t) :: solver(nblocks)   !< one per block of K (casca_assembly)
    logical :: schur = .true.                  !< constraints through the Schur complement
    logical :: auto = .false.                  !< schur chosen at each iteration (casca_solver_choice)
    type(solver_choice_t) :: choice
    logical :: refactored = .false.            !< K factorised since the last choice, not
                                               !< because the pattern was analysed anew
    logical :: analysed = .false.              !< analysed in this iteration
    type(schur_t) :: cache                     !< Z and S of the Schur path
    type(body_frames_t) :: frames              !< the bodies' turn since K was factorised
    integer, allocatable :: last_irn(:), last_jcn(:)   !< constraint pattern last analysed
    type(mass_solver_t) :: mass                !< M by component, for the contact correction
    type(correction_cache_t) :: correction     !< its last C M^-1 C^T, factorised
    !> Kept factors that fail at a step's start (refreshed at its second or third Newton
    !> iteration) start the next fresh_run steps with fresh factors, then are tried again
    !> (a probe); the run doubles while probes fail (a thin plate tumbling at 30 rad/s: its
    !> fibres' stiffness turns with it, and last step's factors made every first increment
    !> worse, three factorisations a step instead of one)
    integer :: fresh_left = 0, fresh_run = 0
    logical :: probing = .false.
    !> auto takes the whole saddle-point matrix for this many more steps: S = C K^-1 C^T
    !> failed where K is near-singular in directions the constraints hold, as a buckled ring
    !> crushed between planes (20 contacts on 20 nodes were called dependent; the saddle-point
    !> matrix went on). Reset with the factors, so a restart takes the same path.
    integer :: saddle_steps = 0
  contains
    procedure :: finish => system_finish
    procedure :: drop_factors => system_drop_factors
    procedure :: start_with_kept => system_start_with_kept
    procedure :: judge_probe => system_judge_probe
    procedure :: new_pattern => system_new_pattern
  end type linear_system_t

contains

  !> Symbolic analysis of each block at its first solve and, with 'saddle', whenever the
  !> constraint pattern in the matrix changes (its one block has the rows after K's equations).
  !> With auto, the path is chosen first (a change of path is a change of pattern).
  subroutine analyse_blocks(ls, model, asm, rows, analyses, err)
    type(linear_system_t), intent(inout) :: ls
    type(model_t), intent(in) :: model
    type(assembly_t), intent(in) :: asm
    type(rows_t), intent(in) :: rows
    integer, intent(inout) :: analyses
    type(error_t), allocatable, intent(out) :: err
    type(error_t), allocatable :: e
    integer, allocatable :: perm(:), irn(:), jcn(:), cirn(:), cjcn(:)
    integer :: nf, n, off, s, i
    logical :: same
    if (ls%auto .and. ls%saddle_steps > 0 .and. asm%ngroups == 1) then
      ls%schur = .false.
    else if (ls%auto) then
      call choose_solver(ls%choice, rows%irn, rows%jcn, rows%val, rows%fval, rows%key, ls%refactored, &
                         asm%ngroups == 1, ls%schur)
      ls%refactored = .false.
    end if
    if (ls%schur) then   ! the constraints stay out of the factorised matrix
      allocate (cirn(0), cjcn(0))
    else
      cirn = rows%irn; cjcn = rows%jcn
    end if
    same = .false.
    if (allocated(ls%last_irn)) then
      if (size(ls%last_irn) == size(cirn)) same = all(ls%last_irn == cirn) .and. all(ls%last_jcn == cjcn)
    end if
    nf = count(cirn == cjcn)   ! multipliers inside the factorised matrix
    do s = 1, nblocks
      if (asm%blk(s)%neq == 0 .or. (ls%solver(s)%analysed .and. same)) cycle
      n = asm%blk(s)%neq; off = asm%blk(s)%off
      irn = asm%irn(asm%blk(s)%first:asm%blk(s)%last)
      jcn = asm%jcn(asm%blk(s)%first:asm%blk(s)%last)
      if (s == 1) n = n + nf
      if (s == 1 .and. asm%blk(s)%host) then
        irn = [irn, cirn]; jcn = [jcn, cjcn]
      end if
      allocate (perm(0))
      if (ls%solver(s)%ordering == 1 .and. asm%blk(s)%host) then
        deallocate (perm); allocate (perm(n))
        call nested_dissection(model%conn, model%nnode, &
                               merge(asm%eq - off, 0, asm%eq > off .and. asm%eq <= off + asm%blk(s)%neq), &
                               asm%blk(s)%neq, perm, e)
        perm(asm%blk(s)%neq + 1:) = [(asm%blk(s)%neq + i, i=1, nf)]   ! multipliers last
      end if
      if (.not. allocated(e)) call ls%solver(s)%analyse(n, irn, jcn, perm, e, asm%blk(s)%ngroups)
      if (allocated(e) .and. .not. allocated(err)) call move_alloc(e, err)
      deallocate (perm)
      analyses = analyses + 1
    end do
    ls%last_irn = cirn; ls%last_jcn = cjcn
    ls%analysed = .not. same
    call share_error(err)
  end subroutine analyse_blocks

  !> Numerical factorisation of every block (with 'saddle', block 1 holds the rows' values).
  !> The blocks factorise apart: all go on, or none.
  subroutine factorise_blocks(ls, model, asm, rows, q, err)
    type(linear_system_t), intent(inout) :: ls
    type(model_t), intent(in) :: model
    type(assembly_t), intent(in) :: asm
    type(rows_t), intent(in) :: rows
    real(dp), intent(in) :: q(:)   !< where K was assembled
    type(error_t), allocatable, intent(out) :: err
    type(error_t), allocatable :: e
    integer :: s
    do s = 1, nblocks
      if (asm%blk(s)%neq == 0) cycle
      associate (a => asm%a(asm%blk(s)%first:asm%blk(s)%last))
        if (asm%blk(s)%host .and. .not. ls%schur) then   ! 'saddle' has one block
          call ls%solver(s)%factorise([a, rows%val], e)
        else
          call ls%solver(s)%factorise(a, e)
        end if
      end associate
      if (allocated(e) .and. .not. allocated(err)) call move_alloc(e, err)
    end do
    call share_error(err)
    call frames_keep(ls%frames, model, asm%eq, q)
    ls%cache%current = .false.   ! Z was made with the old factors
    ls%refactored = .not. ls%analysed   ! (a new pattern's factorisation is the analysis' cost)
  end subroutine factorise_blocks

  !> xx = K^-1 bb block by block (rows: this rank's equations, then, with 'saddle', the
  !> extra multipliers of its one block); zero in the blocks this rank does not host.
  !> Every block is solved before the errors are shared: a block over several ranks is
  !> collective, so a rank that stopped early would leave the others waiting.
  subroutine solve_blocks(ls, asm, bb, xx, extra, err)
    type(linear_system_t), intent(inout) :: ls
    type(assembly_t), intent(in) :: asm
    real(dp), intent(in) :: bb(:, :)
    real(dp), intent(out) :: xx(:, :)
    integer, intent(in) :: extra
    type(error_t), allocatable, intent(out) :: err
    type(error_t), allocatable :: e
    real(dp), allocatable :: bt(:, :)
    xx = 0
    if (ls%schur .and. ls%frames%turned) then   ! (saddle: C is in its factors, never turned)
      bt = bb
      call frames_turn(ls%frames, bt, back=.true.)
      call each_block(bt)
      call frames_turn(ls%frames, xx, back=.false.)
    else
      call each_block(bb)
    end if
  contains
    subroutine each_block(b)
      real(dp), intent(in) :: b(:, :)
      integer :: lo, hi, s
      do s = 1, nblocks
        if (asm%blk(s)%neq == 0) cycle
        lo = asm%blk(s)%off + 1
        hi = asm%blk(s)%off + asm%blk(s)%neq + merge(extra, 0, s == 1)
        call ls%solver(s)%solve(b(lo:hi, :), xx(lo:hi, :), e)
        if (allocated(e) .and. .not. allocated(err)) call move_alloc(e, err)
      end do
      call share_error(err)
    end subroutine each_block
  end subroutine solve_blocks

  !> With kept factors on the Schur path: solve in the frames the free bodies have turned to
  !> since (casca_body_frames); Z made in the old frames is made again.
  subroutine follow_bodies(ls, model, q)
    type(linear_system_t), intent(inout) :: ls
    type(model_t), intent(in) :: model
    real(dp), intent(in) :: q(:)
    if (.not. ls%schur) return
    if (frames_follow(ls%frames, model, q)) ls%cache%current = .false.
  end subroutine follow_bodies

  !> The saddle-point solve: b (asm%neq + nc) holds K's right-hand side then -gap; x the
  !> increment of this rank's equations then dlambda (replicated with 'schur'; on the host
  !> of block 1 with 'saddle'). With 'schur', the columns of Z made with K's factors in use
  !> are kept for the rows of the same key (casca_schur) and only the new rows' are solved
  !> for, with b, in one call; renew: a kept row whose values changed since (the contact
  !> point projected again) is made anew too, as when Newton contracts slowly.
  subroutine kkt_solve(ls, asm, rows, b, renew, x, err)
    type(linear_system_t), intent(inout) :: ls
    type(assembly_t), intent(in) :: asm
    type(rows_t), intent(in) :: rows
    real(dp), intent(in) :: b(:)
    logical, intent(in) :: renew
    real(dp), intent(out) :: x(:)
    type(error_t), allocatable, intent(out) :: err
    real(dp), allocatable :: bb(:, :), yy(:, :)
    integer, allocatable :: col(:), slot(:)
    logical, allocatable :: exact(:)
    logical :: as_kept
    integer :: nc, e, k
    nc = size(rows%gap)
    if (.not. ls%schur .or. nc == 0) then
      allocate (yy(size(b), 1))
      call solve_blocks(ls, asm, reshape(b, [size(b), 1]), yy, merge(0, nc, ls%schur), err)
      x = yy(:, 1)
      return
    end if
    allocate (col(nc), slot(nc), exact(nc))
    call schur_match(ls%cache, rows%irn, rows%jcn, rows%val, rows%fval, rows%key, col, exact)
    if (renew) where (.not. exact) col = 0
    as_kept = all(col == [(k, k=1, nc)])   ! (then the cache is allocated)
    if (as_kept) as_kept = size(ls%cache%key, 2) == nc
    if (as_kept) then   ! Z and S as kept
      allocate (yy(asm%neq, 1))
      call solve_blocks(ls, asm, reshape(b(1:asm%neq), [asm%neq, 1]), yy, 0, err)
      if (allocated(err)) return
    else            ! b and the new rows' columns B^T, in one solve
      slot = 0
      slot(pack([(k, k=1, nc)], col == 0)) = [(1 + k, k=1, count(col == 0))]
      allocate (bb(asm%neq, 1 + count(col == 0)), yy(asm%neq, 1 + count(col == 0)))
      bb = 0
      bb(:, 1) = b(1:asm%neq)
      do e = 1, size(rows%irn)
        k = rows%irn(e) - asm%neq
        if (rows%irn(e) /= rows%jcn(e) .and. slot(k) > 0) bb(rows%jcn(e), slot(k)) = rows%fval(e)
      end do
      call solve_blocks(ls, asm, bb, yy, 0, err)
      if (allocated(err)) return
      call schur_store(ls%cache, asm%neq, rows%irn, rows%jcn, rows%val, rows%fval, rows%key, col, &
                       yy(:, 2:), err)
      if (allocated(err)) return
    end if
    call schur_apply(ls%cache, asm%neq, yy(:, 1), rows%gap, x)
  end subroutine kkt_solve

  !> Negative pivots of the factors in use, summed over the blocks and ranks, plus the
  !> positive eigenvalues of S on the Schur path: the inertia of the saddle-point matrix.
  integer function negative_pivots(ls, asm, nc)
    type(linear_system_t), intent(in) :: ls
    type(assembly_t), intent(in) :: asm
    integer, intent(in) :: nc
    integer :: s
    negative_pivots = 0
    do s = 1, nblocks
      if (asm%blk(s)%neq > 0 .and. asm%blk(s)%host) &
        negative_pivots = negative_pivots + ls%solver(s)%negative_pivots()
    end do
    call sum_all(negative_pivots)
    if (ls%schur .and. nc > 0) negative_pivots = negative_pivots + ls%cache%positive
  end function negative_pivots

  subroutine system_finish(self)
    class(linear_system_t), intent(inout) :: self
    integer :: s
    do s = 1, nblocks
      call self%solver(s)%finish()
    end do
    call self%mass%finish()
  end subroutine system_finish

  !> The next solve refactorises and auto chooses afresh (a restart from a checkpoint takes
  !> the same path).
  subroutine system_drop_factors(self)
    class(linear_system_t), intent(inout) :: self
    type(solver_choice_t) :: fresh
    integer :: s
    do s = 1, nblocks
      call self%solver(s)%drop_factors()
    end do
    self%cache%current = .false.
    if (self%auto) then
      self%choice = fresh
      self%schur = .true.
    end if
    self%saddle_steps = 0
    self%fresh_left = 0; self%fresh_run = 0; self%probing = .false.
  end subroutine system_drop_factors

  !> At a step's first Newton iteration, with factors kept and the last probe judged: use
  !> them (a probe of them), or not, while a failed probe's run of fresh starts lasts.
  logical function system_start_with_kept(self) result(keep)
    class(linear_system_t), intent(inout) :: self
    keep = self%fresh_left == 0
    self%probing = keep
    if (.not. keep) self%fresh_left = self%fresh_left - 1
  end function system_start_with_kept

  !> The open probe's outcome: its step refreshed the factors early (failed) or not
  subroutine system_judge_probe(self, refreshed)
    class(linear_system_t), intent(inout) :: self
    logical, intent(in) :: refreshed
    if (.not. self%probing) return
    self%probing = .false.
    if (refreshed) then
      self%fresh_run = min(64, max(1, 2*self%fresh_run))
      self%fresh_left = self%fresh_run
    else
      self%fresh_run = 0
    end if
  end subroutine system_judge_probe

  !> The unknowns changed: the next solve analyses again.
  subroutine system_new_pattern(self)
    class(linear_system_t), intent(inout) :: self
    integer :: s
    do s = 1, nblocks
      call self%solver(s)%new_pattern()
    end do
    self%cache%current = .false.
  end subroutine system_new_pattern
end module casca_linear_system
