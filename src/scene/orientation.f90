!> The orientation of a mesh of 10-node triangles: reversing it, checking that neighbouring
!> elements agree on it, the signed volume a closed mesh encloses, and distinct nodes at one
!> position (an unmerged seam).
!>
!> An element's normal is the cross product of its xi1 and xi2 tangents, so it follows the
!> order of its vertices. Two elements agree when they traverse their shared edge in opposite
!> directions. A mesh read from a file gets its fibres by averaging the element normals at
!> each node (model.f90), which needs agreement: at an edge of two disagreeing elements the
!> two normals cancel and the fibre is lost.
module casca_orientation
  use casca_kinds, only: dp
  use casca_mesh, only: nen
  use casca_shape_tri10, only: subtri10
  use casca_vectors, only: cross, sort_index
  implicit none
  private
  public :: reverse_elements, edge_census_t, edge_census, signed_volume, vertex_elements
  public :: coincident_t, coincident_nodes, shortest_edge

  !> The node order of the reversed element (casca_mesh's order): vertices 1, 3, 2, so each
  !> edge's two inner nodes are taken from the other end (edge 1-3 of the new element is the
  !> old edge 3-1: nodes 9, 8), the centroid stays.
  integer, parameter :: reversed(nen) = [1, 3, 2, 9, 8, 7, 6, 5, 4, 10]

  !> What the edges between vertex nodes say about a mesh's orientation
  type :: edge_census_t
    integer :: disagree = 0   !< edges of two elements that traverse them the same way
    integer :: open = 0       !< edges of one element (the mesh's boundary)
    integer :: branch = 0     !< edges of three or more elements
    integer :: elem(2) = 0    !< the first disagreeing pair of elements ...
    integer :: node(2) = 0    !< ... and their shared edge's end nodes
  end type edge_census_t

  !> Distinct nodes at one position: how many pairs, and the first (lowest numbers)
  type :: coincident_t
    integer :: pairs = 0
    integer :: node(2) = 0
  end type coincident_t

contains

  !> The pairs of distinct nodes of x(3, nnode) within tol of each other. The nodes are sorted
  !> by their projection on a direction along no mesh line or plane a mesh is likely drawn
  !> on (x . d, |d| = 1: two nodes within tol are within tol on it), and each is compared
  !> with those after it until the projection differs by more than tol: n log n for the sort,
  !> and a sweep over the few nodes whose projections fall that close.
  pure function coincident_nodes(x, tol) result(cn)
    real(dp), intent(in) :: x(:, :), tol
    type(coincident_t) :: cn
    real(dp), parameter :: d(3) = [1._dp, sqrt(2._dp), sqrt(3._dp)]/sqrt(6._dp)
    real(dp), allocatable :: p(:)
    integer, allocatable :: order(:)
    integer :: k, m, i, j
    p = matmul(d, x)
    call sort_index(p, order)
    do k = 1, size(order)
      i = order(k)
      do m = k + 1, size(order)
        j = order(m)
        if (p(j) - p(i) > tol) exit
        if (norm2(x(:, i) - x(:, j)) > tol) cycle
        cn%pairs = cn%pairs + 1
        if (cn%node(1) == 0 .or. min(i, j) < cn%node(1)) cn%node = [min(i, j), max(i, j)]
      end do
    end do
  end function coincident_nodes

  !> Shortest side of the triangle of vertices xv(3, 3)
  pure real(dp) function shortest_edge(xv) result(l)
    real(dp), intent(in) :: xv(3, 3)
    l = min(norm2(xv(:, 1) - xv(:, 2)), norm2(xv(:, 2) - xv(:, 3)), norm2(xv(:, 3) - xv(:, 1)))
  end function shortest_edge

  !> Reverse the orientation of every element of conn(nen, nelem): the normals flip.
  pure subroutine reverse_elements(conn)
    integer, intent(inout) :: conn(:, :)
    conn = conn(reversed, :)
  end subroutine reverse_elements

  !> The elements at each vertex node of conn(nen, nelem): at(start(n) : start(n+1) - 1)
  pure subroutine vertex_elements(conn, nnode, start, at)
    integer, intent(in) :: conn(:, :), nnode
    integer, allocatable, intent(out) :: start(:), at(:)
    integer, allocatable :: fill(:)
    integer :: e, i, j
    allocate (start(nnode + 1), fill(nnode))
    start = 0
    do e = 1, size(conn, 2)
      start(conn(1:3, e) + 1) = start(conn(1:3, e) + 1) + 1
    end do
    start(1) = 1
    do i = 1, nnode
      start(i + 1) = start(i + 1) + start(i)
    end do
    allocate (at(start(nnode + 1) - 1))
    fill = start(1:nnode)
    do e = 1, size(conn, 2)
      do j = 1, 3
        at(fill(conn(j, e))) = e
        fill(conn(j, e)) = fill(conn(j, e)) + 1
      end do
    end do
  end subroutine vertex_elements

  !> Every edge between vertex nodes of conn(nen, nelem) (nodes 1..nnode), sorted into
  !> agreeing, disagreeing (of two elements), open (of one) and branching (of three or more)
  !> ones. Elements are found through the
  !> elements at each vertex node, so the work is the mesh's size times a vertex's valence.
  pure function edge_census(conn, nnode) result(ec)
    integer, intent(in) :: conn(:, :), nnode
    type(edge_census_t) :: ec
    integer, allocatable :: start(:), at(:)
    integer :: e, f, j, k, a, b, nshare, ja, other
    logical :: lowest
    call vertex_elements(conn, nnode, start, at)
    do e = 1, size(conn, 2)
      do j = 1, 3   ! edge a -> b of element e
        a = conn(j, e); b = conn(mod(j, 3) + 1, e)
        nshare = 0; other = 0; lowest = .true.
        do k = start(a), start(a + 1) - 1
          f = at(k)
          if (f == e .or. all(conn(1:3, f) /= b)) cycle
          nshare = nshare + 1; other = f
          lowest = lowest .and. f > e   ! (each edge is counted from its lowest element)
        end do
        if (nshare == 0) ec%open = ec%open + 1
        if (.not. lowest) cycle
        if (nshare > 1) ec%branch = ec%branch + 1
        if (nshare /= 1) cycle
        ! (a branching edge, a T-junction of shells, has no orientation to agree on)
        ja = findloc(conn(1:3, other), a, dim=1)
        if (conn(mod(ja, 3) + 1, other) == b) then   ! the other element runs a -> b too
          ec%disagree = ec%disagree + 1
          if (ec%elem(1) == 0) then
            ec%elem = [e, other]; ec%node = [a, b]
          end if
        end if
      end do
    end do
  end function edge_census

  !> Volume enclosed by the surface x(3, :), conn(nen, nelem), signed by its orientation
  !> (> 0: the normals point out): the divergence theorem over its 9 linear sub-triangles per
  !> element, sum of x1 . (x2 x x3) / 6; exact for the chords' polyhedron. Meaningful for a
  !> closed mesh only.
  pure real(dp) function signed_volume(x, conn) result(v)
    real(dp), intent(in) :: x(:, :)
    integer, intent(in) :: conn(:, :)
    integer :: e, t
    v = 0
    do e = 1, size(conn, 2)
      do t = 1, size(subtri10, 2)
        associate (n => conn(subtri10(:, t), e))
          v = v + dot_product(x(:, n(1)), cross(x(:, n(2)), x(:, n(3))))
        end associate
      end do
    end do
    v = v/6
  end function signed_volume
end module casca_orientation
