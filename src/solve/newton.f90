!> Newton-Raphson on r(q) = f_int(q) [+ inertia] - f_ext = 0 with the analytic tangent,
!> factorised by MUMPS. With contact, each iteration solves the saddle-point system
!>     [ K  C^T ] [ dq      ]   [ -r - C^T lambda ]
!>     [ C  0   ] [ dlambda ] = [ -g              ]
!> Convergence: the largest increment, relative to the size of the scene, below tol, with a
!> settled active set. With reuse, a factorisation is kept across iterations and steps while
!> each iteration shrinks the increment at least fourfold (modified Newton: only the force is
!> assembled then); the incremental form above makes a stale matrix change the path, never
!> the converged answer.
module casca_newton
  use casca_kinds, only: dp
  use casca_error, only: error_t, fatal_error
  use casca_model, only: model_t
  use casca_assembly, only: assembly_t, assemble
  use casca_mumps_solver, only: sparse_solver_t
  use casca_contact, only: contact_t, contact_update, contact_release, contact_rows
  use casca_mpi, only: is_root
  use casca_metis, only: nested_dissection
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
    type(sparse_solver_t), intent(inout) :: solver
    real(dp), intent(inout) :: q(:)
    real(dp), intent(in) :: fext(:)
    type(newton_opts_t), intent(in) :: opts
    type(newton_report_t), intent(out) :: rep
    type(error_t), allocatable, intent(out) :: err
    real(dp), intent(in), optional :: cm, qs(:)
    type(contact_t), intent(inout), optional :: contact
    real(dp), allocatable :: r(:), x(:), b(:), cval(:), gap(:)
    integer, allocatable :: cirn(:), cjcn(:)
    integer :: it, i, nc, added, released, k
    real(dp) :: nrm
    logical :: settled, fresh

    allocate (r(model%ndof))
    if (present(contact)) contact%changes = 0
    do it = 1, min(opts%max_iter, max_hist)
      nc = 0
      call timer_start(t_contact)
      if (present(contact)) then
        call contact_update(contact, model, q, contact%changes < max_set_changes, added, &
                            reproject=it <= 2)
        nc = contact%nact
        call contact_rows(contact, model, asm%eq, asm%neq, cirn, cjcn, cval, gap)
      else
        allocate (cirn(0), cjcn(0), cval(0), gap(0))
      end if
      call timer_stop(t_contact)
      call timer_start(t_analysis)
      call analyse_if_needed()
      call timer_stop(t_analysis)
      if (allocated(err)) return

      ! a new matrix unless the kept one still contracts the increment fourfold
      ! (decided from replicated figures, so alike on every rank)
      fresh = .not. (opts%reuse .and. solver%factored)
      if (.not. fresh .and. it >= 3) fresh = rep%incr(it - 1) > 0.25_dp*rep%incr(it - 2)
      if (it > 8) fresh = .true.
      call timer_start(t_assembly)
      call assemble(model, asm, q, fresh, r, rep%energy, cm, qs)
      r = r - fext
      call timer_stop(t_assembly)
      if (fresh) then
        call timer_start(t_factor)
        if (is_root()) then
          call solver%factorise([asm%a, cval], err)
        else
          call solver%factorise(asm%a, err)
        end if
        call timer_stop(t_factor)
        if (allocated(err)) return
        rep%factorisations = rep%factorisations + 1
      end if

      allocate (b(asm%neq + nc), x(asm%neq + nc))
      if (is_root()) then
        do i = 1, model%ndof
          if (asm%eq(i) > 0) b(asm%eq(i)) = -r(i)
        end do
        do k = 1, size(cirn)   ! the multipliers' force C^T lambda, with the current rows
          if (cirn(k) /= cjcn(k)) &
            b(cjcn(k)) = b(cjcn(k)) - cval(k)*contact%act(cirn(k) - asm%neq)%lambda
        end do
        b(asm%neq + 1:) = -gap
      end if
      call timer_start(t_solve)
      call solver%solve(b, x, err)
      call timer_stop(t_solve)
      if (allocated(err)) return
      do i = 1, model%ndof
        if (asm%eq(i) > 0) q(i) = q(i) + x(asm%eq(i))
      end do
      if (nc > 0) contact%act(1:nc)%lambda = contact%act(1:nc)%lambda + x(asm%neq + 1:)
      nrm = maxval(abs(x(1:asm%neq)))/model%length
      deallocate (b, x, cirn, cjcn, cval, gap)
      rep%iters = it
      rep%incr(it) = nrm
      if (.not. (nrm <= 1e6_dp)) then   ! also catches NaN
        call fatal_error(err, 'Newton iteration diverged')
        return
      end if
      if (nrm > opts%tol) cycle
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
        rep%neg_pivots = solver%negative_pivots()   ! of the factors in use
        return
      end if
    end do
  contains
    !> symbolic analysis at the first solve and whenever the constraint rows change
    subroutine analyse_if_needed()
      integer, allocatable :: perm(:)
      if (solver%analysed) then
        if (.not. present(contact)) return
        if (same_pattern()) return
      end if
      allocate (perm(0))
      if (solver%ordering == 1 .and. is_root()) then
        deallocate (perm); allocate (perm(asm%neq + nc))
        call nested_dissection(model%conn, model%nnode, asm%eq, asm%neq, perm, err)
        if (allocated(err)) return
        perm(asm%neq + 1:) = [(asm%neq + i, i=1, nc)]   ! multipliers last
      end if
      if (is_root()) then
        call solver%analyse(asm%neq + nc, [asm%irn, cirn], [asm%jcn, cjcn], perm, err)
      else
        call solver%analyse(asm%neq + nc, asm%irn, asm%jcn, perm, err)
      end if
      rep%analyses = rep%analyses + 1
      if (present(contact)) then
        contact%last_irn = cirn; contact%last_jcn = cjcn
      end if
    end subroutine analyse_if_needed

    logical function same_pattern()
      same_pattern = .false.
      if (.not. allocated(contact%last_irn)) return
      if (size(contact%last_irn) /= size(cirn)) return
      same_pattern = all(contact%last_irn == cirn) .and. all(contact%last_jcn == cjcn)
    end function same_pattern
  end subroutine newton_solve
end module casca_newton
