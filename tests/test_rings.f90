!> A scene the unit tests share: two thesis rings (R 1, width 0.2, 20 cubic triangles around,
!> h 0.05, steel) that overlap obliquely by 0.1 m on a line 0.4 m from the axis, so that
!> several impactor nodes of ring 1 are inside ring 2, off the line of centres; their contact
!> rows and the dynamic tangent factorised, for the tests of the Schur path.
module casca_test_rings
  use casca_kinds, only: dp
  use casca_error, only: error_t
  use casca_mesh, only: mesh_t
  use casca_mesh_generators, only: mesh_ring
  use casca_model, only: model_t, model_add_body, model_finalize, reference_state, dof
  use casca_assembly, only: assembly_t, assemble
  use casca_contact, only: contact_t, contact_init
  use casca_contact_active_set, only: contact_update
  use casca_contact_rows, only: contact_rows
  use casca_obstacle, only: obstacle_t
  use casca_linear_system, only: linear_system_t, rows_t, analyse_blocks, factorise_blocks
  use casca_mpi, only: sum_all, max_all
  implicit none
  private
  public :: overlapping_rings, ring_rows, factorised, saddle_residuals

contains

  !> model: the two rings, finalised (error stop if the generator or the model fails)
  subroutine overlapping_rings(model)
    type(model_t), intent(out) :: model
    type(mesh_t) :: ring
    type(error_t), allocatable :: err
    call mesh_ring(1._dp, 0.2_dp, 20, 1, ring, err)
    if (allocated(err)) error stop 'mesh'
    call model_add_body(model, 'ring1', ring, 210e9_dp, 0.3_dp, 7700._dp, 0.05_dp)
    ring%x(1, :) = ring%x(1, :) + 1.9_dp
    ring%x(2, :) = ring%x(2, :) + 0.4_dp
    call model_add_body(model, 'ring2', ring, 210e9_dp, 0.3_dp, 7700._dp, 0.05_dp)
    call model_finalize(model, err)
    if (allocated(err)) error stop 'model'
  end subroutine overlapping_rings

  !> q: the rings where they are (turned by the rotation turn about the origin, if given: the
  !> nodes' positions and fibres); rows: ring 1's nodes on ring 2 there (mid-surfaces), in
  !> asm's equations
  subroutine ring_rows(model, asm, q, rows, turn)
    type(model_t), intent(in) :: model
    type(assembly_t), intent(in) :: asm
    real(dp), allocatable, intent(out) :: q(:)
    type(rows_t), intent(out) :: rows
    real(dp), intent(in), optional :: turn(3, 3)
    type(contact_t) :: c
    integer :: added, n
    allocate (q(model%ndof))
    call reference_state(model, q)
    if (present(turn)) then
      do n = 1, model%nnode
        q(dof(n, 1):dof(n, 3)) = matmul(turn, q(dof(n, 1):dof(n, 3)))
        q(dof(n, 4):dof(n, 6)) = matmul(turn, q(dof(n, 4):dof(n, 6)))
      end do
    end if
    call contact_init(model, reshape([1, 2], [2, 1]), [obstacle_t ::], 1e-9_dp, .false., c)
    call contact_update(c, model, q, .true., added)
    call contact_rows(c, model, asm%eq, asm%neq, rows%irn, rows%jcn, rows%val, rows%gap, rows%key, rows%fval)
  end subroutine ring_rows

  !> ls: K + cm M at q analysed and factorised for the rows (cm = 4e8 = 1/(beta dt^2), dt 50 us)
  subroutine factorised(model, asm, q, rows, ls)
    type(model_t), intent(in) :: model
    type(assembly_t), intent(inout) :: asm
    real(dp), intent(in) :: q(:)
    type(rows_t), intent(in) :: rows
    type(linear_system_t), intent(inout) :: ls
    type(error_t), allocatable :: err
    real(dp), allocatable :: r(:)
    real(dp) :: energy
    integer :: analyses
    allocate (r(model%ndof))
    call assemble(model, asm, q, .true., r, energy, 4e8_dp, q)
    analyses = 0
    call analyse_blocks(ls, model, asm, rows, analyses, err)
    if (allocated(err)) error stop 'analysis'
    call factorise_blocks(ls, model, asm, rows, q, err)
    if (allocated(err)) error stop 'factorisation'
  end subroutine factorised

  !> The saddle-point system's residuals at x = [dq; dl] for b = [f; -gap], from K's entries
  !> (each of this rank's blocks) and the rows: force, |K dq + B^T dl - f| over
  !> max(|f|, |K dq|, |B^T dl|) on each rank's equations, the largest over the ranks; gap,
  !> |C dq + gap| / |gap| with C dq summed over the ranks
  subroutine saddle_residuals(asm, rows, b, x, force, gap)
    type(assembly_t), intent(in) :: asm
    type(rows_t), intent(in) :: rows
    real(dp), intent(in) :: b(:), x(:)
    real(dp), intent(out) :: force, gap
    real(dp), allocatable :: kx(:), btl(:), g(:)
    integer :: e, k, n
    n = asm%neq
    allocate (kx(n), btl(n), g(size(rows%gap)))
    kx = 0; btl = 0; g = 0
    do k = 1, size(asm%blk)
      do e = asm%blk(k)%first, asm%blk(k)%last
        associate (ia => asm%irn(e) + asm%blk(k)%off, ja => asm%jcn(e) + asm%blk(k)%off)
          kx(ia) = kx(ia) + asm%a(e)*x(ja)
          if (ia /= ja) kx(ja) = kx(ja) + asm%a(e)*x(ia)
        end associate
      end do
    end do
    do e = 1, size(rows%irn)
      if (rows%irn(e) == rows%jcn(e)) cycle
      btl(rows%jcn(e)) = btl(rows%jcn(e)) + rows%fval(e)*x(rows%irn(e))
      g(rows%irn(e) - n) = g(rows%irn(e) - n) + rows%val(e)*x(rows%jcn(e))
    end do
    call sum_all(g)
    force = maxval(abs(kx + btl - b(1:n)))/max(maxval(abs(b(1:n))), maxval(abs(kx)), maxval(abs(btl)))
    call max_all(force)
    gap = maxval(abs(g + rows%gap))/maxval(abs(rows%gap))
  end subroutine saddle_residuals
end module casca_test_rings
