!> Newton-Raphson on r(q) = f_int(q) [+ inertia] - f_ext = 0 with the analytic tangent,
!> factorised by MUMPS. With contact, each iteration solves the saddle-point system
!>     [ K  C^T ] [ dq      ]   [ -r - C^T lambda ]
!>     [ C  0   ] [ dlambda ] = [ -g              ]
!> Convergence: the largest increment, relative to the size of the scene, below tol, with a
!> settled active set. By default (contact solver 'schur') the constraints are not put in the
!> factorised matrix: K alone is factorised, with a pattern that never changes, and the system
!> is solved through the Schur complement C K^-1 C^T; 'saddle' factorises the whole
!> saddle-point matrix (re-analysed whenever the constraint pattern changes). K's diagonal
!> blocks (casca_assembly) each have a MUMPS instance: solver(s) for block s. With reuse, a
!> factorisation is kept across iterations and steps while
!> each iteration shrinks the increment at least fourfold (modified Newton: only the force is
!> assembled then); the incremental form above makes a stale matrix change the path, never
!> the converged answer.
module casca_newton
  use casca_kinds, only: dp
  use casca_error, only: error_t, fatal_error
  use casca_model, only: model_t
  use casca_assembly, only: assembly_t, assemble, nblocks
  use casca_mumps_solver, only: sparse_solver_t
  use casca_contact, only: contact_t, contact_update, contact_release, contact_rows
  use casca_mpi, only: is_root, sum_all, share_error
  use casca_metis, only: nested_dissection
  use casca_lapack, only: dsyev, dgetrf, dgetrs
  use casca_timers, only: timer_start, timer_stop, t_assembly, t_contact, t_analysis, t_factor, &
                          t_solve
  implicit none
  private
  public :: newton_opts_t, newton_report_t, newton_solve

  integer, parameter :: max_hist = 100
  integer, parameter :: max_set_changes = 12   !< active-set changes per step before settling

  type :: newton_opts_t
    real(dp) :: tol = 1e-10_dp   !< max |dq| / scene size
    integer :: max_iter = 25
    logical :: reuse = .true.    !< keep factorisations while they converge fast enough
  end type newton_opts_t

  type :: newton_report_t
    integer :: iters = 0
    logical :: converged = .false.
    real(dp) :: incr(max_hist) = 0   !< max |dq| / scene size at each iteration
    real(dp) :: energy = 0           !< strain energy at the last assembled iterate
    integer :: neg_pivots = 0        !< of the last factorisation (inertia)
    integer :: analyses = 0          !< symbolic analyses done in this solve
    integer :: factorisations = 0    !< numerical factorisations done in this solve
  end type newton_report_t

contains

  subroutine newton_solve(model, asm, solver, q, fext, opts, rep, err, cm, qs, contact)
    type(model_t), intent(in) :: model
    type(assembly_t), intent(inout) :: asm
    type(sparse_solver_t), intent(inout) :: solver(nblocks)
    real(dp), intent(inout) :: q(:)
    real(dp), intent(in) :: fext(:)
    type(newton_opts_t), intent(in) :: opts
    type(newton_report_t), intent(out) :: rep
    type(error_t), allocatable, intent(out) :: err
    real(dp), intent(in), optional :: cm, qs(:)
    type(contact_t), intent(inout), optional :: contact
    type(error_t), allocatable :: e
    real(dp), allocatable :: x2(:, :), r(:), x(:), b(:), cval(:), gap(:), cval_f(:), dq(:)
    integer, allocatable :: cirn(:), cjcn(:), cirn_f(:), cjcn_f(:)
    integer :: it, i, nc, added, released, k, schur_positive, s
    real(dp) :: nrm
    logical :: settled, fresh, schur, renew_z

    allocate (r(model%ndof), cirn_f(0), cjcn_f(0), cval_f(0))
    if (asm%neq_total == 0) then   ! every body is frozen this step: nothing to solve
      rep%converged = .true.
      return
    end if
    schur = .false.
    if (present(contact)) schur = contact%schur
    schur_positive = 0
    if (present(contact)) contact%changes = 0
    do it = 1, min(opts%max_iter, max_hist)
      nc = 0
      call timer_start(t_contact)
      if (present(contact)) then
        call contact_update(contact, model, q, contact%changes < max_set_changes, added, &
                            reproject=it <= 1)
        nc = contact%nact
        call contact_rows(contact, model, asm%eq, asm%neq, cirn, cjcn, cval, gap)
      else
        allocate (cirn(0), cjcn(0), cval(0), gap(0))
      end if
      call timer_stop(t_contact)
      if (schur) then   ! the constraints stay out of the factorised matrix
        deallocate (cirn_f, cjcn_f, cval_f); allocate (cirn_f(0), cjcn_f(0), cval_f(0))
      else
        cirn_f = cirn; cjcn_f = cjcn; cval_f = cval
      end if
      call timer_start(t_analysis)
      call analyse_if_needed()
      call timer_stop(t_analysis)
      call share_error(err)
      if (allocated(err)) return

      ! a new matrix unless the kept one still contracts the increment fourfold (decided from
      ! replicated figures, so alike on every rank). With constraints, slow contraction comes
      ! first from the constraint rows (their normal is held): the Schur cache is renewed
      ! first, K only if contraction stays poor.
      fresh = .not. (opts%reuse .and. solver(1)%factored)   ! block 1: on every rank
      renew_z = .false.
      if (it >= 3) renew_z = rep%incr(it - 1) > 0.25_dp*rep%incr(it - 2)
      if (.not. fresh) then
        if (schur .and. nc > 0) then
          if (it >= 4) fresh = rep%incr(it - 1) > 0.5_dp*rep%incr(it - 2)
        else
          fresh = renew_z
        end if
      end if
      if (it > 8) fresh = .true.
      call timer_start(t_assembly)
      call assemble(model, asm, q, fresh, r, rep%energy, cm, qs)
      r = r - fext
      call timer_stop(t_assembly)
      if (fresh) then
        call timer_start(t_factor)
        do s = 1, nblocks
          if (asm%blk(s)%neq == 0) cycle
          associate (a => asm%a(asm%blk(s)%first:asm%blk(s)%last))
            if (asm%blk(s)%host) then   ! cval_f: 'saddle' only, which has one block
              call solver(s)%factorise([a, cval_f], e)
            else
              call solver(s)%factorise(a, e)
            end if
          end associate
          if (allocated(e) .and. .not. allocated(err)) call move_alloc(e, err)
        end do
        call timer_stop(t_factor)
        call share_error(err)   ! the blocks factorise apart: all go on, or none
        if (allocated(err)) return
        rep%factorisations = rep%factorisations + 1
        if (present(contact)) contact%z_current = .false.
      end if

      allocate (b(asm%neq + nc), x(asm%neq + nc))
      b = 0
      do i = 1, model%ndof
        if (asm%eq(i) > 0) b(asm%eq(i)) = -r(i)
      end do
      do k = 1, size(cirn)   ! the multipliers' force C^T lambda, with the current rows
        if (cirn(k) /= cjcn(k)) &
          b(cjcn(k)) = b(cjcn(k)) - cval(k)*contact%act(cirn(k) - asm%neq)%lambda
      end do
      b(asm%neq + 1:) = -gap
      call timer_start(t_solve)
      if (schur .and. nc > 0) then
        call schur_solve()
      else
        allocate (x2(size(b), 1))
        call solve_blocks(reshape(b, [size(b), 1]), x2, nc)
        x = x2(:, 1)
        deallocate (x2)
      end if
      if (allocated(err)) then
        call timer_stop(t_solve); return
      end if
      ! the whole increment on every rank: each block's host gives its part (x is zero in
      ! the blocks a rank does not host), rank 0 the multipliers' (every rank has them with
      ! 'schur'; rank 0 is the only host with 'saddle')
      allocate (dq(model%ndof + nc))
      dq = 0
      do i = 1, model%ndof
        if (asm%eq(i) > 0) dq(i) = x(asm%eq(i))
      end do
      if (is_root()) dq(model%ndof + 1:) = x(asm%neq + 1:)
      call sum_all(dq)
      call timer_stop(t_solve)
      q = q + dq(1:model%ndof)
      if (nc > 0) contact%act(1:nc)%lambda = contact%act(1:nc)%lambda + dq(model%ndof + 1:)
      nrm = maxval(abs(dq(1:model%ndof)))/model%length
      deallocate (b, x, dq, cirn, cjcn, cval, gap)
      rep%iters = it
      rep%incr(it) = nrm
      if (.not. (nrm <= 1e6_dp)) then   ! also catches NaN
        call fatal_error(err, 'Newton iteration diverged')
        return
      end if
      if (.not. small_enough()) cycle
      settled = .true.
      if (present(contact)) then
        if (contact%changes < max_set_changes) then
          ! converged for this set: release tensile multipliers, look for new penetrations
          call timer_start(t_contact)
          call contact_release(contact, released)
          call contact_update(contact, model, q, .true., added, reproject=.false.)
          call timer_stop(t_contact)
          settled = released == 0 .and. added == 0
        end if
      end if
      if (settled) then
        rep%converged = .true.
        rep%neg_pivots = 0   ! of the factors in use, summed over the blocks
        do s = 1, nblocks
          if (asm%blk(s)%neq > 0 .and. asm%blk(s)%host) &
            rep%neg_pivots = rep%neg_pivots + solver(s)%negative_pivots()
        end do
        call sum_all(rep%neg_pivots)
        if (schur .and. nc > 0) rep%neg_pivots = rep%neg_pivots + schur_positive
        return
      end if
    end do
  contains
    !> The iterate's error, not the last increment, within tol: with contraction rho =
    !> incr(it) / incr(it-1) < 1/2 what is left after this increment is at most about
    !> incr(it) rho / (1 - rho) (a geometric tail), which saves the last iteration whose only
    !> use would be to measure it (replicated figures: alike on every rank)
    logical function small_enough()
      real(dp) :: rho
      small_enough = nrm <= opts%tol
      if (small_enough .or. it < 2) return
      rho = nrm/max(rep%incr(it - 1), tiny(1._dp))
      if (rho < 0.5_dp) small_enough = nrm*rho/(1 - rho) <= opts%tol
    end function small_enough

    !> The saddle-point system through the Schur complement of K: Z = K^-1 C^T, S = C Z,
    !> y = K^-1 b, S dlambda = C y + g, dq = y - Z dlambda. Z and S are kept (with the rows
    !> they were made from) while the constraints (node, element), K's factors and good
    !> contraction stay, so most iterations cost one solve. Each block's host holds its rows
    !> of Z and y (zero elsewhere); S and C y are summed over the ranks and S is factorised on
    !> every rank, so dlambda is replicated. The inertia of the saddle-point matrix is that of
    !> K plus the positive eigenvalues of S.
    subroutine schur_solve()
      real(dp), allocatable :: bb(:, :), yy(:, :), sc(:, :), rhs(:), eig(:), work(:), y(:)
      integer :: e, kk, info, lwork
      logical :: valid
      valid = .false.
      if (allocated(contact%z_node)) then   ! replicated figures: every rank decides alike
        valid = .not. renew_z .and. contact%z_current .and. size(contact%z_node) == nc
        if (valid) valid = all(contact%z_node == contact%act(1:nc)%node) .and. &
                           all(contact%z_elem == contact%act(1:nc)%elem)
      end if
      if (.not. valid) then   ! Z and S from the current rows: nc + 1 right-hand sides
        allocate (bb(asm%neq, nc + 1), yy(asm%neq, nc + 1))
        bb = 0
        bb(:, 1) = b(1:asm%neq)
        do e = 1, size(cirn)
          if (cirn(e) /= cjcn(e)) bb(cjcn(e), 1 + cirn(e) - asm%neq) = cval(e)
        end do
        call solve_blocks(bb, yy, 0)
        if (allocated(err)) return
        contact%z_irn = cirn; contact%z_jcn = cjcn; contact%z_val = cval
        contact%z_node = contact%act(1:nc)%node; contact%z_elem = contact%act(1:nc)%elem
        contact%z_current = .true.
        contact%z = yy(:, 2:)
        y = yy(:, 1)
        if (allocated(contact%s)) deallocate (contact%s)
        allocate (contact%s(nc, nc))
        contact%s = 0
        do e = 1, size(cirn)
          if (cirn(e) == cjcn(e)) cycle
          kk = cirn(e) - asm%neq
          contact%s(kk, :) = contact%s(kk, :) + cval(e)*contact%z(cjcn(e), :)
        end do
        call sum_all(contact%s)
        contact%s = 0.5_dp*(contact%s + transpose(contact%s))
        sc = contact%s
        lwork = max(1, 3*nc)
        allocate (eig(nc), work(lwork))
        call dsyev('N', 'U', nc, sc, nc, eig, work, lwork, info)
        contact%z_positive = count(eig > 0)
        if (allocated(contact%z_ipiv)) deallocate (contact%z_ipiv)
        allocate (contact%z_ipiv(nc))
        call dgetrf(nc, nc, contact%s, nc, contact%z_ipiv, info)
        if (info /= 0) contact%z_ipiv = -1   ! dependent constraints: no correction
      else                    ! the kept Z and S: one right-hand side
        allocate (yy(asm%neq, 1))
        call solve_blocks(reshape(b(1:asm%neq), [asm%neq, 1]), yy, 0)
        if (allocated(err)) return
        y = yy(:, 1)
      end if
      allocate (rhs(nc))
      rhs = 0   ! C_kept y + g: the matrix is [K, C_kept^T; C_kept, 0] throughout
      do e = 1, size(contact%z_irn)
        if (contact%z_irn(e) == contact%z_jcn(e)) cycle
        kk = contact%z_irn(e) - asm%neq
        rhs(kk) = rhs(kk) + contact%z_val(e)*y(contact%z_jcn(e))
      end do
      call sum_all(rhs)
      rhs = rhs + gap
      if (contact%z_ipiv(1) > 0) then
        call dgetrs('N', nc, 1, contact%s, nc, contact%z_ipiv, rhs, nc, info)
      else
        rhs = 0
      end if
      x(1:asm%neq) = y - matmul(contact%z, rhs)
      x(asm%neq + 1:) = rhs
      schur_positive = contact%z_positive
    end subroutine schur_solve

    !> xx = K^-1 bb block by block (rows: this rank's equations, then, with 'saddle', the
    !> extra multipliers of its one block); zero in the blocks this rank does not host.
    !> Every block is solved before the errors are shared: a block over several ranks is
    !> collective, so a rank that stopped early would leave the others waiting.
    subroutine solve_blocks(bb, xx, extra)
      real(dp), intent(in) :: bb(:, :)
      real(dp), intent(out) :: xx(:, :)
      integer, intent(in) :: extra
      integer :: lo, hi, s
      xx = 0
      do s = 1, nblocks
        if (asm%blk(s)%neq == 0) cycle
        lo = asm%blk(s)%off + 1
        hi = asm%blk(s)%off + asm%blk(s)%neq + merge(extra, 0, s == 1)
        call solver(s)%solve(bb(lo:hi, :), xx(lo:hi, :), e)
        if (allocated(e) .and. .not. allocated(err)) call move_alloc(e, err)
      end do
      call share_error(err)
    end subroutine solve_blocks

    !> symbolic analysis of each block at its first solve and whenever the constraint rows
    !> in the matrix change ('saddle', whose one block has them after K's equations)
    subroutine analyse_if_needed()
      integer, allocatable :: perm(:), irn(:), jcn(:)
      integer :: nf, n, off
      logical :: same
      same = .true.
      if (present(contact)) same = same_pattern()
      nf = count(cirn_f == cjcn_f)   ! multipliers inside the factorised matrix
      do s = 1, nblocks
        if (asm%blk(s)%neq == 0 .or. (solver(s)%analysed .and. same)) cycle
        n = asm%blk(s)%neq; off = asm%blk(s)%off
        irn = asm%irn(asm%blk(s)%first:asm%blk(s)%last)
        jcn = asm%jcn(asm%blk(s)%first:asm%blk(s)%last)
        if (s == 1) n = n + nf
        if (s == 1 .and. asm%blk(s)%host) then
          irn = [irn, cirn_f]; jcn = [jcn, cjcn_f]
        end if
        allocate (perm(0))
        if (solver(s)%ordering == 1 .and. asm%blk(s)%host) then
          deallocate (perm); allocate (perm(n))
          call nested_dissection(model%conn, model%nnode, &
                                 merge(asm%eq - off, 0, asm%eq > off .and. asm%eq <= off + asm%blk(s)%neq), &
                                 asm%blk(s)%neq, perm, e)
          perm(asm%blk(s)%neq + 1:) = [(asm%blk(s)%neq + i, i=1, nf)]   ! multipliers last
        end if
        if (.not. allocated(e)) call solver(s)%analyse(n, irn, jcn, perm, e, asm%blk(s)%ngroups)
        if (allocated(e) .and. .not. allocated(err)) call move_alloc(e, err)
        deallocate (perm)
        rep%analyses = rep%analyses + 1
      end do
      if (present(contact)) then
        contact%last_irn = cirn_f; contact%last_jcn = cjcn_f
      end if
    end subroutine analyse_if_needed

    logical function same_pattern()
      same_pattern = .false.
      if (.not. allocated(contact%last_irn)) return
      if (size(contact%last_irn) /= size(cirn_f)) return
      same_pattern = all(contact%last_irn == cirn_f) .and. all(contact%last_jcn == cjcn_f)
    end function same_pattern
  end subroutine newton_solve
end module casca_newton
