!> A scene the unit tests share: two thesis rings (R 1, width 0.2, 20 cubic triangles around,
!> h 0.05, steel) that overlap obliquely by 0.1 m on a line 0.4 m from the axis, so that
!> several impactor nodes of ring 1 are inside ring 2, off the line of centres.
module casca_test_rings
  use casca_kinds, only: dp
  use casca_error, only: error_t
  use casca_mesh, only: mesh_t
  use casca_mesh_generators, only: mesh_ring
  use casca_model, only: model_t, model_add_body, model_finalize
  implicit none
  private
  public :: overlapping_rings

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
end module casca_test_rings
