!> Structured 10-node cubic triangle meshes of the benchmark shells: a cylindrical ring strip,
!> a closed sphere (subdivided icosahedron) and a flat rectangular plate/strip.
!>
!> Every generator places the nodes of each cubic element on the integer lattice of its
!> parameter domain (three lattice steps per element edge) and numbers global nodes from an
!> exact integer key of that lattice, so shared nodes are merged without any floating-point
!> tolerance search. Elements are oriented so that dx/dxi1 x dx/dxi2 points along the outward
!> normal; curved surfaces get their nodes placed exactly on the analytic surface and
!> mesh%normal holds the exact unit normal there.
module casca_mesh_generators
  use casca_kinds, only: dp, pi
  use casca_error, only: error_t, fatal_error
  use casca_mesh, only: mesh_t, nen
  use casca_vectors, only: cross
  use casca_deck, only: body_cfg_t
  implicit none
  private
  public :: mesh_ring, mesh_sphere, mesh_plate, generated_mesh, body_elements

  !> Most elements a generator makes: beyond it the lattice indices (3n+1)^2 leave 32 bits
  !> and no machine would hold the model anyway
  real(dp), parameter, public :: max_generated_elements = 1e7_dp

  !> Local lattice offsets (in thirds of an element edge, along the element's (xi1, xi2)) of the
  !> ten nodes, in the casca / Gmsh TRI10 order documented in casca_mesh.
  integer, parameter :: node_a(nen) = [0, 3, 0, 1, 2, 2, 1, 0, 0, 1]
  integer, parameter :: node_b(nen) = [0, 0, 3, 0, 0, 1, 2, 2, 1, 1]

contains

  !> The mesh generator b%mesh (ring, sphere, plate, strip) makes from body b's sizes; an error
  !> for any other kind.
  subroutine generated_mesh(b, mesh, err)
    type(body_cfg_t), intent(in) :: b
    type(mesh_t), intent(out) :: mesh
    type(error_t), allocatable, intent(out) :: err
    select case (b%mesh)
    case ('ring')
      call mesh_ring(b%radius, b%width, b%n_around, b%n_across, mesh, err)
    case ('sphere')
      call mesh_sphere(b%radius, b%n_div, mesh, err)
    case ('plate', 'strip')
      call mesh_plate(b%lx, b%ly, b%nx, b%ny, mesh, err)
    case default
      call fatal_error(err, 'unknown kind "'//trim(b%mesh)//'" (ring, sphere, plate, strip)')
    end select
  end subroutine generated_mesh

  !> Number of elements body b's generator makes from its sizes; 0 for a mesh file.
  pure real(dp) function body_elements(b) result(n)
    type(body_cfg_t), intent(in) :: b
    select case (b%mesh)
    case ('ring')
      n = generated_elements(b%mesh, b%n_around, b%n_across)
    case ('sphere')
      n = generated_elements(b%mesh, b%n_div, 0)
    case ('plate', 'strip')
      n = generated_elements(b%mesh, b%nx, b%ny)
    case default
      n = 0
    end select
  end function body_elements

  !> Number of elements the generator kind ('ring', 'sphere', 'plate', 'strip') makes from
  !> its sizes (n1, n2) = (n_around, n_across), (n_div, -) or (nx, ny); in real arithmetic,
  !> so that absurd sizes are seen before they overflow.
  pure real(dp) function generated_elements(kind, n1, n2) result(n)
    character(len=*), intent(in) :: kind
    integer, intent(in) :: n1, n2
    select case (kind)
    case ('sphere')
      n = 20*real(n1, dp)**2
    case default
      n = 2*real(n1, dp)*real(n2, dp)
    end select
  end function generated_elements

  !> An error if the generator kind would make more than max_generated_elements
  subroutine check_count(kind, n1, n2, err)
    character(len=*), intent(in) :: kind
    integer, intent(in) :: n1, n2
    type(error_t), allocatable, intent(out) :: err
    character(len=24) :: num
    if (generated_elements(kind, n1, n2) <= max_generated_elements) return
    write (num, '(es9.2)') generated_elements(kind, n1, n2)
    call fatal_error(err, 'mesh_'//kind//': the sizes give '//trim(adjustl(num))// &
                     ' elements, more than the 1e7 a generator makes')
  end subroutine check_count

  !> Cylindrical strip: axis z, mid-surface radius `radius`, z in [-width/2, width/2].
  !> xi1 runs with the angle and xi2 with z, so e_theta x e_z = e_r points outward.
  subroutine mesh_ring(radius, width, n_around, n_across, mesh, err)
    real(dp), intent(in) :: radius, width
    integer, intent(in) :: n_around, n_across
    type(mesh_t), intent(out) :: mesh
    type(error_t), allocatable, intent(out) :: err
    integer :: ni, nj, i, j, id
    real(dp) :: theta, z

    if (.not. (radius > 0.0_dp) .or. .not. (width > 0.0_dp)) then
      call fatal_error(err, "mesh_ring: radius and width must be positive")
      return
    end if
    ! Fewer than 3 segments would make elements whose corners are (anti)podal or coincident.
    if (n_around < 3 .or. n_across < 1) then
      call fatal_error(err, "mesh_ring: need n_around >= 3 and n_across >= 1")
      return
    end if
    call check_count('ring', n_around, n_across, err)
    if (allocated(err)) return

    ni = 3*n_around       ! lattice points around (periodic: index ni is index 0)
    nj = 3*n_across + 1   ! lattice points across
    call structured_conn(n_around, n_across, .true., mesh)
    mesh%nnode = ni*nj
    allocate (mesh%x(3, mesh%nnode), mesh%normal(3, mesh%nnode))
    do j = 0, nj - 1
      z = -0.5_dp*width + width*real(j, dp)/real(nj - 1, dp)
      do i = 0, ni - 1
        ! The angle itself (not a chord fraction) puts every cubic node on the cylinder.
        theta = 2.0_dp*pi*real(i, dp)/real(ni, dp)
        id = lattice_id(i, j, ni)
        mesh%x(:, id) = [radius*cos(theta), radius*sin(theta), z]
        mesh%normal(:, id) = [cos(theta), sin(theta), 0.0_dp]
      end do
    end do
  end subroutine mesh_ring

  !> Flat rectangle [0,lx] x [0,ly] in the xy plane with normal +z (also used for strips).
  subroutine mesh_plate(lx, ly, nx, ny, mesh, err)
    real(dp), intent(in) :: lx, ly
    integer, intent(in) :: nx, ny
    type(mesh_t), intent(out) :: mesh
    type(error_t), allocatable, intent(out) :: err
    integer :: ni, nj, i, j, id

    if (.not. (lx > 0.0_dp) .or. .not. (ly > 0.0_dp)) then
      call fatal_error(err, "mesh_plate: lx and ly must be positive")
      return
    end if
    if (nx < 1 .or. ny < 1) then
      call fatal_error(err, "mesh_plate: need nx >= 1 and ny >= 1")
      return
    end if
    call check_count('plate', nx, ny, err)
    if (allocated(err)) return

    ni = 3*nx + 1
    nj = 3*ny + 1
    call structured_conn(nx, ny, .false., mesh)
    mesh%nnode = ni*nj
    allocate (mesh%x(3, mesh%nnode), mesh%normal(3, mesh%nnode))
    do j = 0, nj - 1
      do i = 0, ni - 1
        id = lattice_id(i, j, ni)
        mesh%x(:, id) = [lx*real(i, dp)/real(ni - 1, dp), ly*real(j, dp)/real(nj - 1, dp), 0.0_dp]
        mesh%normal(:, id) = [0.0_dp, 0.0_dp, 1.0_dp]
      end do
    end do
  end subroutine mesh_plate

  !> Connectivity of an nci x ncj grid of cells, two triangles per cell split along the
  !> (0,0)-(3,3) diagonal, both counter-clockwise in the (i, j) lattice. With `periodic`, lattice
  !> column 3*nci wraps to column 0 (closed ring).
  subroutine structured_conn(nci, ncj, periodic, mesh)
    integer, intent(in) :: nci, ncj
    logical, intent(in) :: periodic
    type(mesh_t), intent(inout) :: mesh
    ! Corner lattice offsets of the two triangles of a cell: (0,0),(3,0),(3,3) and (0,0),(3,3),(0,3).
    integer, parameter :: tri_i(3, 2) = reshape([0, 3, 3, 0, 3, 0], [3, 2])
    integer, parameter :: tri_j(3, 2) = reshape([0, 0, 3, 0, 3, 3], [3, 2])
    integer :: ni, ci, cj, t, k, e, i, j

    if (periodic) then
      ni = 3*nci
    else
      ni = 3*nci + 1
    end if
    mesh%nelem = 2*nci*ncj
    allocate (mesh%conn(nen, mesh%nelem))
    e = 0
    do cj = 0, ncj - 1
      do ci = 0, nci - 1
        do t = 1, 2
          e = e + 1
          do k = 1, nen
            ! Node at P1 + a*(P2-P1)/3 + b*(P3-P1)/3: integer because corner offsets are multiples of 3.
            i = 3*ci + tri_i(1, t) + (node_a(k)*(tri_i(2, t) - tri_i(1, t)) + node_b(k)*(tri_i(3, t) - tri_i(1, t)))/3
            j = 3*cj + tri_j(1, t) + (node_a(k)*(tri_j(2, t) - tri_j(1, t)) + node_b(k)*(tri_j(3, t) - tri_j(1, t)))/3
            if (periodic) i = modulo(i, ni)
            mesh%conn(k, e) = lattice_id(i, j, ni)
          end do
        end do
      end do
    end do
  end subroutine structured_conn

  pure integer function lattice_id(i, j, ni)
    integer, intent(in) :: i, j, ni
    lattice_id = j*ni + i + 1
  end function lattice_id

  !> Closed sphere of radius `radius` centred at the origin: each of the 20 icosahedron faces is
  !> split into n_div^2 flat triangles, the cubic lattice points of every flat triangle are
  !> projected radially onto the sphere. Global node numbers come from canonical keys (icosahedron
  !> vertex; icosahedron edge + lattice position from its lower-numbered end; face + interior
  !> lattice point), so the merge is exact and O(n).
  subroutine mesh_sphere(radius, n_div, mesh, err)
    real(dp), intent(in) :: radius
    integer, intent(in) :: n_div
    type(mesh_t), intent(out) :: mesh
    type(error_t), allocatable, intent(out) :: err
    real(dp) :: v(3, 12), p(3)
    integer :: face(3, 20), edge_of(12, 12)
    integer, allocatable :: interior_index(:, :)
    integer :: nl, n_edge_pts, n_face_pts, f, ca, cb, up, k, a, b, e, id, w(3), g(3)
    integer :: corner_a(3), corner_b(3)

    if (.not. (radius > 0.0_dp)) then
      call fatal_error(err, "mesh_sphere: radius must be positive")
      return
    end if
    if (n_div < 1) then
      call fatal_error(err, "mesh_sphere: need n_div >= 1")
      return
    end if
    call check_count('sphere', n_div, 0, err)
    if (allocated(err)) return

    call icosahedron(v, face, edge_of)
    nl = 3*n_div                        ! lattice steps along an icosahedron edge
    n_edge_pts = nl - 1                 ! lattice points strictly inside an edge
    n_face_pts = (nl - 1)*(nl - 2)/2    ! lattice points strictly inside a face

    ! Rank of each interior lattice point (a, b), a, b >= 1, a + b <= nl - 1, within its face.
    allocate (interior_index(0:nl, 0:nl), source=0)
    k = 0
    do b = 1, nl - 2
      do a = 1, nl - 1 - b
        k = k + 1
        interior_index(a, b) = k
      end do
    end do

    mesh%nnode = 12 + 30*n_edge_pts + 20*n_face_pts
    mesh%nelem = 20*n_div**2
    allocate (mesh%x(3, mesh%nnode), mesh%normal(3, mesh%nnode), mesh%conn(nen, mesh%nelem))

    e = 0
    do f = 1, 20
      ! "Up" sub-triangles (a,b),(a+3,b),(a,b+3) and "down" ones (a+3,b),(a+3,b+3),(a,b+3):
      ! both counter-clockwise in (a, b), hence outward like the face itself.
      do up = 1, 2
        do cb = 0, nl - 3, 3
          do ca = 0, nl - 3 - cb, 3
            if (up == 1) then
              corner_a = [ca, ca + 3, ca]
              corner_b = [cb, cb, cb + 3]
            else
              if (ca + cb > nl - 6) cycle
              corner_a = [ca + 3, ca + 3, ca]
              corner_b = [cb, cb + 3, cb + 3]
            end if
            e = e + 1
            do k = 1, nen
              a = corner_a(1) + (node_a(k)*(corner_a(2) - corner_a(1)) + node_b(k)*(corner_a(3) - corner_a(1)))/3
              b = corner_b(1) + (node_a(k)*(corner_b(2) - corner_b(1)) + node_b(k)*(corner_b(3) - corner_b(1)))/3
              ! Integer barycentric weights of the face's vertices, summing to nl.
              w = [nl - a - b, a, b]
              g = face(:, f)
              call canonical_node(w, g, id, p)
              mesh%conn(k, e) = id
              ! The canonical point is computed the same way from every face that shares it.
              mesh%normal(:, id) = p/norm2(p)
              mesh%x(:, id) = radius*mesh%normal(:, id)
            end do
          end do
        end do
      end do
    end do

  contains

    !> Global id and flat-face position of the lattice point with weights w on vertices g.
    subroutine canonical_node(w, g, id, p)
      integer, intent(in) :: w(3), g(3)
      integer, intent(out) :: id
      real(dp), intent(out) :: p(3)
      integer :: nz, lo, hi, t, i
      nz = count(w == 0)
      if (nz == 2) then
        i = maxloc(w, 1)
        id = g(i)
        p = v(:, g(i))
      else if (nz == 1) then
        ! On the edge between the two vertices with non-zero weight; t counts from the lower id.
        lo = huge(1)
        hi = 0
        t = 0
        do i = 1, 3
          if (w(i) == 0) cycle
          if (g(i) < lo) lo = g(i)
          if (g(i) > hi) hi = g(i)
        end do
        do i = 1, 3
          if (g(i) == hi) t = w(i)
        end do
        id = 12 + (edge_of(lo, hi) - 1)*n_edge_pts + t
        p = (real(nl - t, dp)*v(:, lo) + real(t, dp)*v(:, hi))/real(nl, dp)
      else
        id = 12 + 30*n_edge_pts + (f - 1)*n_face_pts + interior_index(w(2), w(3))
        p = (real(w(1), dp)*v(:, g(1)) + real(w(2), dp)*v(:, g(2)) + real(w(3), dp)*v(:, g(3)))/real(nl, dp)
      end if
    end subroutine canonical_node
  end subroutine mesh_sphere

  !> Regular icosahedron with edge length 2: vertices (0,+-1,+-phi) and cyclic permutations.
  !> Faces and edges are found as vertex triples/pairs at distance 2 (no hand-typed table to
  !> get wrong); each face is ordered so its normal points away from the origin.
  subroutine icosahedron(v, face, edge_of)
    real(dp), intent(out) :: v(3, 12)
    integer, intent(out) :: face(3, 20), edge_of(12, 12)
    real(dp) :: phi, c(3)
    integer :: i, j, k, s1, s2, nf, ne, tmp

    phi = 0.5_dp*(1.0_dp + sqrt(5.0_dp))
    k = 0
    do s1 = -1, 1, 2
      do s2 = -1, 1, 2
        v(:, k + 1) = [0.0_dp, real(s1, dp), s2*phi]
        v(:, k + 2) = [real(s1, dp), s2*phi, 0.0_dp]
        v(:, k + 3) = [s2*phi, 0.0_dp, real(s1, dp)]
        k = k + 3
      end do
    end do

    edge_of = 0
    ne = 0
    do i = 1, 11
      do j = i + 1, 12
        if (is_edge(i, j)) then
          ne = ne + 1
          edge_of(i, j) = ne
          edge_of(j, i) = ne
        end if
      end do
    end do

    nf = 0
    do i = 1, 10
      do j = i + 1, 11
        if (.not. is_edge(i, j)) cycle
        do k = j + 1, 12
          if (.not. (is_edge(i, k) .and. is_edge(j, k))) cycle
          nf = nf + 1
          face(:, nf) = [i, j, k]
          c = cross(v(:, j) - v(:, i), v(:, k) - v(:, i))
          if (dot_product(c, v(:, i) + v(:, j) + v(:, k)) < 0.0_dp) then
            tmp = face(2, nf)
            face(2, nf) = face(3, nf)
            face(3, nf) = tmp
          end if
        end do
      end do
    end do

  contains

    logical function is_edge(p, q)
      integer, intent(in) :: p, q
      is_edge = abs(sum((v(:, p) - v(:, q))**2) - 4.0_dp) < 1.0e-9_dp
    end function is_edge
  end subroutine icosahedron

end module casca_mesh_generators
