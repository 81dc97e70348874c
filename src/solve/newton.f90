!> Newton-Raphson on r(q) = f_int(q) [+ inertia] - f_ext = 0 with the analytic tangent,
!> factorised by MUMPS. Convergence: the largest parameter increment, relative to the size
!> of the scene, below tol.
module casca_newton
  use casca_kinds, only: dp
  use casca_error, only: error_t, fatal_error
  use casca_model, only: model_t
  use casca_assembly, only: assembly_t, assemble
  use casca_mumps_solver, only: sparse_solver_t
  use casca_mpi, only: is_root
  use casca_metis, only: nested_dissection
  implicit none
  private
  public :: newton_opts_t, newton_report_t, newton_solve

  integer, parameter :: max_hist = 100

  type :: newton_opts_t
    real(dp) :: tol = 1e-10_dp   !< max |dq| / scene size
    integer :: max_iter = 25
  end type newton_opts_t

  type :: newton_report_t
    integer :: iters = 0
    logical :: converged = .false.
    real(dp) :: incr(max_hist) = 0   !< max |dq| / scene size at each iteration
    real(dp) :: energy = 0           !< strain energy at the last assembled iterate
  end type newton_report_t

contains

  subroutine newton_solve(model, asm, solver, q, fext, opts, rep, err, cm, qs)
    type(model_t), intent(in) :: model
    type(assembly_t), intent(inout) :: asm
    type(sparse_solver_t), intent(inout) :: solver
    real(dp), intent(inout) :: q(:)
    real(dp), intent(in) :: fext(:)
    type(newton_opts_t), intent(in) :: opts
    type(newton_report_t), intent(out) :: rep
    type(error_t), allocatable, intent(out) :: err
    real(dp), intent(in), optional :: cm, qs(:)
    real(dp), allocatable :: r(:), x(:), b(:)
    integer, allocatable :: perm(:)
    integer :: it, i
    real(dp) :: nrm

    allocate (r(model%ndof), x(asm%neq), b(asm%neq))
    if (.not. solver%analysed) then
      allocate (perm(0))
      if (solver%ordering == 1 .and. is_root()) then
        deallocate (perm); allocate (perm(asm%neq))
        call nested_dissection(model%conn, model%nnode, asm%eq, asm%neq, perm, err)
        if (allocated(err)) return
      end if
      call solver%analyse(asm%neq, asm%irn, asm%jcn, perm, err)
      if (allocated(err)) return
    end if
    do it = 1, min(opts%max_iter, max_hist)
      call assemble(model, asm, q, .true., r, rep%energy, cm, qs)
      r = r - fext
      call solver%factorise(asm%a, err)
      if (allocated(err)) return
      if (is_root()) then
        do i = 1, model%ndof
          if (asm%eq(i) > 0) b(asm%eq(i)) = -r(i)
        end do
      end if
      call solver%solve(b, x, err)
      if (allocated(err)) return
      do i = 1, model%ndof
        if (asm%eq(i) > 0) q(i) = q(i) + x(asm%eq(i))
      end do
      nrm = maxval(abs(x))/model%length
      rep%iters = it
      rep%incr(it) = nrm
      if (.not. (nrm <= 1e6_dp)) then   ! also catches NaN
        call fatal_error(err, 'Newton iteration diverged')
        return
      end if
      if (nrm <= opts%tol) then
        rep%converged = .true.
        return
      end if
    end do
  end subroutine newton_solve
end module casca_newton
