!> A surface mesh of 10-node cubic triangles.
!>
!> Node order inside an element (the only order casca uses; Gmsh TRI10 and VTK_LAGRANGE_TRIANGLE
!> share it): vertices 1,2,3 at (xi1,xi2) = (0,0),(1,0),(0,1); nodes 4,5 on edge 1-2 at 1/3 and
!> 2/3 from node 1; nodes 6,7 on edge 2-3 from node 2; nodes 8,9 on edge 3-1 from node 3;
!> node 10 at the centroid.
module casca_mesh
  use casca_kinds, only: dp
  implicit none
  private
  public :: mesh_t, nen, node_set_t

  integer, parameter :: nen = 10   !< nodes per element

  !> A named node set (a Gmsh physical group): its nodes in the mesh's numbering, ascending.
  type :: node_set_t
    character(len=:), allocatable :: name
    integer, allocatable :: nodes(:)
  end type node_set_t

  type :: mesh_t
    integer :: nnode = 0
    integer :: nelem = 0
    real(dp), allocatable :: x(:, :)       !< (3, nnode) mid-surface coordinates
    real(dp), allocatable :: normal(:, :)  !< (3, nnode) exact unit outward normals, or size 0 if unknown
    integer, allocatable :: conn(:, :)     !< (nen, nelem) node numbers, 1-based
    type(node_set_t), allocatable :: sets(:)   !< physical groups of a mesh file (else none)
  end type mesh_t
end module casca_mesh
