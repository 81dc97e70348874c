!> The acceleration a loaded body starts with: the equation of motion at t = 0,
!> M a = F - f_int(q) - f_p(q), solved on the free position and fibre parameters (the
!> thickness parameter has no mass). A second-order scheme started from a = 0 under a load
!> already acting is first order: generalized-alpha's cantilever under a tip load applied at
!> rest converged as dt^1 (2.0, 1.1, 0.61, 0.27% of the peak at 2, 1, 0.5, 0.25 ms).
module casca_start_acceleration
  use casca_kinds, only: dp
  use casca_error, only: error_t
  use casca_model, only: model_t, dof
  use casca_assembly, only: assembly_t, assemble
  use casca_follower_loads, only: add_follower_loads
  use casca_mass_solver, only: mass_solver_t, mass_setup
  implicit none
  private
  public :: loaded_acceleration

contains

  !> qdd on the nodes of the bodies in which = M^-1 (fext - f_int(q) - f_p(q)), the rest of qdd
  !> unchanged. ms: the run's mass solver if it has one (set up), else one is made for this
  !> alone. Collective (the forces are summed over the ranks).
  subroutine loaded_acceleration(model, asm, q, fext, which, qdd, err, ms)
    type(model_t), intent(in) :: model
    type(assembly_t), intent(inout) :: asm
    real(dp), intent(in) :: q(:), fext(:)
    logical, intent(in) :: which(:)
    real(dp), intent(inout) :: qdd(:)
    type(error_t), allocatable, intent(out) :: err
    type(mass_solver_t), intent(inout), optional, target :: ms
    type(mass_solver_t), allocatable, target :: own   ! (allocatable: large, kept off the stack)
    type(mass_solver_t), pointer :: m
    real(dp), allocatable :: r(:), a(:)
    real(dp) :: energy, scale
    integer :: b
    allocate (r(model%ndof), a(model%ndof))
    call assemble(model, asm, q, .false., r, energy)
    r = r - fext
    call add_follower_loads(model, asm, q, .false., r, scale)
    if (present(ms)) then
      m => ms
    else
      allocate (own)
      call mass_setup(model, own, err)
      m => own
    end if
    if (.not. allocated(err)) call m%solve(-r, a, err)
    if (allocated(own)) call own%finish()
    if (allocated(err)) return
    do b = 1, model%nbody
      if (.not. which(b)) cycle
      associate (f => dof(model%body(b)%node_first, 1), l => dof(model%body(b)%node_last, 7))
        qdd(f:l) = a(f:l)
      end associate
    end do
  end subroutine loaded_acceleration
end module casca_start_acceleration
