!> Checks of the mesh generators and the Gmsh reader/writer against independent answers:
!> analytic surfaces and areas, counts from closed-form formulas or from Gmsh's own API, and the
!> topology of closed surfaces. The cubic shape functions are written out here again on purpose,
!> so that a wrong node order in the library cannot hide behind a matching wrong order in a test.
!>
!> Usage: test_mesh_io [data-folder]   (default tests/data; holds the gmsh_tri10_*.msh files)
!> Scratch files go to $TMPDIR (default /tmp) and are deleted afterwards.
program test_mesh_io
  use casca_kinds, only: dp, pi
  use casca_error, only: error_t
  use casca_mesh, only: mesh_t
  use casca_mesh_generators, only: mesh_ring, mesh_sphere, mesh_plate
  use casca_gmsh_io, only: read_gmsh, write_gmsh
  implicit none

  ! 7-point degree-5 rule on the reference triangle (weights sum to its area 1/2).
  real(dp), parameter :: s15 = sqrt(15.0_dp)
  real(dp), parameter :: qa1 = (6.0_dp - s15)/21.0_dp, qb1 = (9.0_dp + 2.0_dp*s15)/21.0_dp
  real(dp), parameter :: qa2 = (6.0_dp + s15)/21.0_dp, qb2 = (9.0_dp - 2.0_dp*s15)/21.0_dp
  real(dp), parameter :: qw1 = (155.0_dp - s15)/2400.0_dp, qw2 = (155.0_dp + s15)/2400.0_dp
  real(dp), parameter :: qxi(2, 7) = reshape([1.0_dp/3, 1.0_dp/3, qa1, qa1, qa1, qb1, qb1, qa1, &
                                              qa2, qa2, qa2, qb2, qb2, qa2], [2, 7])
  real(dp), parameter :: qw(7) = [9.0_dp/80, qw1, qw1, qw1, qw2, qw2, qw2]

  integer :: nfail = 0
  character(len=:), allocatable :: data_dir, tmp_dir, tag

  call setup()
  call test_ring()
  call test_sphere()
  call test_plate()
  call test_round_trip()
  call test_gmsh_files()
  call test_bad_files()

  if (nfail > 0) then
    write (*, '(i0,a)') nfail, ' check(s) failed'
    error stop 1
  end if
  write (*, '(a)') 'all checks passed'

contains

  subroutine setup()
    character(len=4096) :: buf
    integer :: n, st, cnt
    call get_command_argument(1, buf, n, st)
    if (st == 0 .and. n > 0) then
      data_dir = trim(buf)
    else
      data_dir = 'tests/data'
    end if
    call get_environment_variable('TMPDIR', buf, n, st)
    if (st == 0 .and. n > 0) then
      tmp_dir = trim(buf)
    else
      tmp_dir = '/tmp'
    end if
    ! Clock-based tag so that concurrent runs do not share scratch files.
    call system_clock(cnt)
    write (buf, '(a,i0)') 'casca_test_mesh_io_', cnt
    tag = trim(buf)
  end subroutine setup

  ! ---------------------------------------------------------------------------------------------
  ! Generators

  subroutine test_ring()
    real(dp), parameter :: r = 2.0_dp, w = 0.5_dp
    type(mesh_t) :: m
    type(error_t), allocatable :: err
    real(dp) :: rerr, nerr
    integer :: i
    call mesh_ring(r, w, 20, 1, m, err)
    if (.not. check_ok('ring_generate', err)) return
    call check_int('ring_nelem', m%nelem, 40)
    call check_int('ring_nnode', m%nnode, 240)
    call check_int('ring_nodes_referenced', count_referenced(m), 240)
    call check_small('ring_min_node_separation_ok', merge(0.0_dp, 1.0_dp, min_separation(m) > 1.0e-9_dp*r), 0.0_dp)
    rerr = 0.0_dp
    nerr = 0.0_dp
    do i = 1, m%nnode
      rerr = max(rerr, abs(hypot(m%x(1, i), m%x(2, i)) - r))
      nerr = max(nerr, norm2(m%normal(:, i) - [m%x(1, i), m%x(2, i), 0.0_dp]/r))
    end do
    call check_small('ring_radius_maxerr', rerr, 1.0e-12_dp*r)
    call check_small('ring_z_range_excess', max(0.0_dp, maxval(abs(m%x(3, :))) - 0.5_dp*w), 1.0e-15_dp)
    call check_small('ring_normal_maxerr', nerr, 1.0e-12_dp)
    call check_small('ring_area_relerr', abs(mesh_area(m)/(2.0_dp*pi*r*w) - 1.0_dp), 1.0e-4_dp)
    call check_int('ring_badly_oriented', count_misoriented(m, 'cylinder'), 0)
    ! Open strip: 20 axial edges (one of them the seam) and 20 diagonals are shared by two
    ! elements; the 2*20 edges on the rims are used once.
    call check_int('ring_edges_used_twice', count_edges(m, 2), 20 + 20)
    call check_int('ring_edges_used_once', count_edges(m, 1), 40)
  end subroutine test_ring

  subroutine test_sphere()
    real(dp), parameter :: r = 1.3_dp
    type(mesh_t) :: m
    type(error_t), allocatable :: err
    real(dp) :: rerr, nerr
    integer :: i, nv
    call mesh_sphere(r, 6, m, err)
    if (.not. check_ok('sphere_generate', err)) return
    call check_int('sphere_nelem', m%nelem, 720)
    call check_int('sphere_nnode', m%nnode, 9*720/2 + 2)
    call check_int('sphere_nodes_referenced', count_referenced(m), 3242)
    call check_small('sphere_min_node_separation_ok', merge(0.0_dp, 1.0_dp, min_separation(m) > 1.0e-9_dp*r), 0.0_dp)
    rerr = 0.0_dp
    nerr = 0.0_dp
    do i = 1, m%nnode
      rerr = max(rerr, abs(norm2(m%x(:, i)) - r))
      nerr = max(nerr, norm2(m%normal(:, i) - m%x(:, i)/r))
    end do
    call check_small('sphere_radius_maxerr', rerr, 1.0e-12_dp*r)
    call check_small('sphere_normal_maxerr', nerr, 1.0e-12_dp)
    call check_small('sphere_area_relerr', abs(mesh_area(m)/(4.0_dp*pi*r**2) - 1.0_dp), 1.0e-4_dp)
    call check_int('sphere_badly_oriented', count_misoriented(m, 'sphere'), 0)
    ! Closed, consistently oriented surface: each directed edge has exactly one reversed twin
    ! carrying the same two edge nodes; no edge is used once.
    call check_int('sphere_edges_used_once', count_edges(m, 1), 0)
    call check_int('sphere_edges_used_twice', count_edges(m, 2), 3*720/2)
    call check_int('sphere_edges_without_reversed_twin', count_unmatched_twins(m), 0)
    nv = count_corner_nodes(m)
    call check_int('sphere_euler_characteristic', nv - 3*720/2 + 720, 2)
  end subroutine test_sphere

  subroutine test_plate()
    real(dp), parameter :: lx = 2.0_dp, ly = 0.7_dp
    type(mesh_t) :: m
    type(error_t), allocatable :: err
    call mesh_plate(lx, ly, 4, 3, m, err)
    if (.not. check_ok('plate_generate', err)) return
    call check_int('plate_nelem', m%nelem, 2*4*3)
    call check_int('plate_nnode', m%nnode, (3*4 + 1)*(3*3 + 1))
    call check_int('plate_nodes_referenced', count_referenced(m), (3*4 + 1)*(3*3 + 1))
    call check_small('plate_area_relerr', abs(mesh_area(m)/(lx*ly) - 1.0_dp), 1.0e-12_dp)
    call check_small('plate_max_abs_z', maxval(abs(m%x(3, :))), 0.0_dp)
    call check_small('plate_bbox_err', maxval(abs([minval(m%x(1, :)), minval(m%x(2, :)), &
                     maxval(m%x(1, :)) - lx, maxval(m%x(2, :)) - ly])), 1.0e-15_dp)
    call check_int('plate_badly_oriented', count_misoriented(m, 'plane'), 0)
    call check_int('plate_edges_used_once', count_edges(m, 1), 2*(4 + 3))
  end subroutine test_plate

  ! ---------------------------------------------------------------------------------------------
  ! Gmsh I/O

  subroutine test_round_trip()
    type(mesh_t) :: m, back
    type(error_t), allocatable :: err
    character(len=:), allocatable :: path
    real(dp) :: dx
    integer :: e, k, u, ios
    path = tmp_dir // '/' // tag // '_roundtrip.msh'
    call mesh_sphere(0.8_dp, 3, m, err)
    if (.not. check_ok('roundtrip_generate', err)) return
    call write_gmsh(path, m, err)
    if (.not. check_ok('roundtrip_write', err)) return
    call read_gmsh(path, back, err)
    open (newunit=u, file=path, status='old', iostat=ios)
    if (ios == 0) close (u, status='delete')
    if (.not. check_ok('roundtrip_read', err)) return
    call check_int('roundtrip_nnode', back%nnode, m%nnode)
    call check_int('roundtrip_nelem', back%nelem, m%nelem)
    if (back%nnode /= m%nnode .or. back%nelem /= m%nelem) return
    call check_int('roundtrip_normal_size', size(back%normal), 0)
    ! Compare element by element through coordinates: independent of node numbering.
    dx = 0.0_dp
    do e = 1, m%nelem
      do k = 1, 10
        dx = max(dx, norm2(back%x(:, back%conn(k, e)) - m%x(:, m%conn(k, e))))
      end do
    end do
    call check_small('roundtrip_element_node_coord_maxerr', dx, 1.0e-12_dp)
    call check_int('roundtrip_nodes_referenced', count_referenced(back), m%nnode)
  end subroutine test_round_trip

  subroutine test_gmsh_files()
    type(mesh_t) :: m
    type(error_t), allocatable :: err
    real(dp) :: rerr
    integer :: i

    ! Quarter cylinder r = 1, 0 <= z <= 2; 44 type-21 elements as reported by gmsh's
    ! getElementsByType(21) in make_gmsh_files.py.
    call read_gmsh(data_dir // '/gmsh_tri10_v41.msh', m, err)
    if (check_ok('gmsh41_read', err)) then
      call check_int('gmsh41_nelem', m%nelem, 44)
      call check_int('gmsh41_normal_size', size(m%normal), 0)
      call check_int('gmsh41_nodes_referenced', count_referenced(m), m%nnode)
      rerr = 0.0_dp
      do i = 1, m%nnode
        rerr = max(rerr, abs(hypot(m%x(1, i), m%x(2, i)) - 1.0_dp))
      end do
      call check_small('gmsh41_cylinder_radius_maxerr', rerr, 1.0e-6_dp)
      call check_small('gmsh41_area_relerr', abs(mesh_area(m)/(0.5_dp*pi*1.0_dp*2.0_dp) - 1.0_dp), 1.0e-4_dp)
      call check_int('gmsh41_edges_used_once', count_edges(m, 1), &
                     count_once_edges_on_planes(m, [1, 2, 3, 3], [0.0_dp, 0.0_dp, 0.0_dp, 2.0_dp]))
    end if

    ! Lateral wall of a cylinder r = 1, -0.5 <= z <= 0.5 (closed around: Gmsh's seam nodes are
    ! shared); 46 type-21 elements as reported by gmsh.
    call read_gmsh(data_dir // '/gmsh_tri10_v22.msh', m, err)
    if (check_ok('gmsh22_read', err)) then
      call check_int('gmsh22_nelem', m%nelem, 46)
      call check_int('gmsh22_normal_size', size(m%normal), 0)
      call check_int('gmsh22_nodes_referenced', count_referenced(m), m%nnode)
      rerr = 0.0_dp
      do i = 1, m%nnode
        rerr = max(rerr, abs(hypot(m%x(1, i), m%x(2, i)) - 1.0_dp))
      end do
      call check_small('gmsh22_cylinder_radius_maxerr', rerr, 1.0e-6_dp)
      call check_small('gmsh22_area_relerr', abs(mesh_area(m)/(2.0_dp*pi) - 1.0_dp), 1.0e-4_dp)
      call check_int('gmsh22_edges_used_once', count_edges(m, 1), &
                     count_once_edges_on_planes(m, [3, 3], [-0.5_dp, 0.5_dp]))
    end if
  end subroutine test_gmsh_files

  !> Edges used by one element whose two corners lie on one of the planes x(axes(k)) = values(k)
  !> (the true boundary): equal to all edges used once only if every interior edge is shared.
  integer function count_once_edges_on_planes(m, axes, values) result(n)
    type(mesh_t), intent(in) :: m
    integer, intent(in) :: axes(:)
    real(dp), intent(in) :: values(:)
    integer, parameter :: ea(3) = [1, 2, 3], eb(3) = [2, 3, 1]
    real(dp), parameter :: tol = 1.0e-9_dp
    real(dp) :: xa(3), xb(3)
    integer :: e, k, p
    n = 0
    do e = 1, m%nelem
      do k = 1, 3
        if (edge_uses(m, m%conn(ea(k), e), m%conn(eb(k), e)) /= 1) cycle
        xa = m%x(:, m%conn(ea(k), e))
        xb = m%x(:, m%conn(eb(k), e))
        do p = 1, size(axes)
          if (abs(xa(axes(p)) - values(p)) < tol .and. abs(xb(axes(p)) - values(p)) < tol) then
            n = n + 1
            exit
          end if
        end do
      end do
    end do
  end function count_once_edges_on_planes

  subroutine test_bad_files()
    character(len=:), allocatable :: p
    character(len=*), parameter :: nl = achar(10)

    p = tmp_dir // '/' // tag // '_missing.msh'
    call expect_error('bad_missing_file', p, '', .false.)

    p = tmp_dir // '/' // tag // '_truncated_nodes.msh'
    call write_text(p, '$MeshFormat' // nl // '4.1 0 8' // nl // '$EndMeshFormat' // nl // '$Nodes' // nl // &
                    '1 10 1 10' // nl // '2 1 0 10' // nl // '1' // nl // '2' // nl // '3' // nl)
    call expect_error('bad_truncated_nodes', p, ':10:', .true.)

    ! Cut off in the middle of a node's line (no line end): named at that line, and said so.
    p = tmp_dir // '/' // tag // '_cut_line.msh'
    call write_text(p, '$MeshFormat' // nl // '4.1 0 8' // nl // '$EndMeshFormat' // nl // '$Nodes' // nl // &
                    '1 2 1 2' // nl // '2 1 0 2' // nl // '1' // nl // '2' // nl // '0 0 0' // nl // '1 0')
    call expect_error('bad_cut_line', p, ':10:', .true., 'the file ends in the middle of this line')

    p = tmp_dir // '/' // tag // '_version30.msh'
    call write_text(p, '$MeshFormat' // nl // '3.0 0 8' // nl // '$EndMeshFormat' // nl)
    call expect_error('bad_version_3_0', p, ':2:', .true.)

    p = tmp_dir // '/' // tag // '_binary.msh'
    call write_text(p, '$MeshFormat' // nl // '4.1 1 8' // nl // '$EndMeshFormat' // nl)
    call expect_error('bad_binary', p, ':2:', .true.)

    p = tmp_dir // '/' // tag // '_element_header.msh'
    call write_text(p, '$MeshFormat' // nl // '4.1 0 8' // nl // '$EndMeshFormat' // nl // '$Nodes' // nl // &
                    '0 0 0 0' // nl // '$EndNodes' // nl // '$Elements' // nl // '1 2 x' // nl // '$EndElements' // nl)
    call expect_error('bad_elements_header', p, ':8:', .true.)

    ! Element on line 10 refers to node 99, never defined.
    p = tmp_dir // '/' // tag // '_undefined_node.msh'
    call write_text(p, '$MeshFormat' // nl // '2.2 0 8' // nl // '$EndMeshFormat' // nl // '$Nodes' // nl // &
                    '1' // nl // '1 0 0 0' // nl // '$EndNodes' // nl // '$Elements' // nl // '1' // nl // &
                    '1 21 2 0 1 1 1 1 1 1 1 1 1 1 99' // nl // '$EndElements' // nl)
    call expect_error('bad_undefined_node', p, ':10:', .true.)

    ! Only a 2-node line element: nothing casca can use.
    p = tmp_dir // '/' // tag // '_no_tri10.msh'
    call write_text(p, '$MeshFormat' // nl // '2.2 0 8' // nl // '$EndMeshFormat' // nl // '$Nodes' // nl // &
                    '2' // nl // '1 0 0 0' // nl // '2 1 0 0' // nl // '$EndNodes' // nl // '$Elements' // nl // &
                    '1' // nl // '1 1 2 0 1 1 2' // nl // '$EndElements' // nl)
    call expect_error('bad_no_tri10', p, ':12:', .true.)
  end subroutine test_bad_files

  !> read_gmsh(path) must fail with a message naming the file (and containing `where`).
  subroutine expect_error(name, path, where, delete, also)
    character(len=*), intent(in) :: name, path, where
    logical, intent(in) :: delete
    character(len=*), intent(in), optional :: also   !< a phrase the message must hold too
    type(mesh_t) :: m
    type(error_t), allocatable :: err
    integer :: u, ios
    call read_gmsh(path, m, err)
    if (delete) then
      open (newunit=u, file=path, status='old', iostat=ios)
      if (ios == 0) close (u, status='delete')
    end if
    if (.not. allocated(err)) then
      call report(.false., name, 'no error', 'an error naming ' // path // where)
    else if (index(err%message, path // where) /= 1) then
      call report(.false., name, '"' // err%message // '"', 'a message starting with ' // path // where)
    else if (present(also)) then
      call report(index(err%message, also) > 0, name, '"' // err%message // '"', 'a message saying ' // also)
    else
      call report(.true., name, '"' // err%message // '"', '')
    end if
  end subroutine expect_error

  subroutine write_text(path, text)
    character(len=*), intent(in) :: path, text
    integer :: u, ios
    open (newunit=u, file=path, status='replace', access='stream', form='unformatted', iostat=ios)
    if (ios /= 0) then
      call report(.false., 'write_scratch_file', path, 'writable')
      return
    end if
    write (u) text
    close (u)
  end subroutine write_text

  ! ---------------------------------------------------------------------------------------------
  ! Independent geometry: cubic Lagrange triangle in barycentric L1 = 1-xi1-xi2, L2 = xi1, L3 = xi2

  !> Shape functions and their xi1/xi2 derivatives at (xi1, xi2), casca/Gmsh TRI10 order.
  subroutine shape(xi1, xi2, n, d1, d2)
    real(dp), intent(in) :: xi1, xi2
    real(dp), intent(out) :: n(10), d1(10), d2(10)
    real(dp) :: l(3), dl(10, 3)
    ! Edge nodes 4..9 as (nearer vertex i, other vertex j).
    integer, parameter :: ei(4:9) = [1, 2, 2, 3, 3, 1], ej(4:9) = [2, 1, 3, 2, 1, 3]
    integer :: k, i, j
    l = [1.0_dp - xi1 - xi2, xi1, xi2]
    dl = 0.0_dp
    do k = 1, 3
      n(k) = 0.5_dp*l(k)*(3.0_dp*l(k) - 1.0_dp)*(3.0_dp*l(k) - 2.0_dp)
      dl(k, k) = 0.5_dp*(27.0_dp*l(k)**2 - 18.0_dp*l(k) + 2.0_dp)
    end do
    do k = 4, 9
      i = ei(k)
      j = ej(k)
      n(k) = 4.5_dp*l(i)*l(j)*(3.0_dp*l(i) - 1.0_dp)
      dl(k, i) = 4.5_dp*l(j)*(6.0_dp*l(i) - 1.0_dp)
      dl(k, j) = 4.5_dp*l(i)*(3.0_dp*l(i) - 1.0_dp)
    end do
    n(10) = 27.0_dp*l(1)*l(2)*l(3)
    dl(10, :) = 27.0_dp*[l(2)*l(3), l(1)*l(3), l(1)*l(2)]
    ! d/dxi1 = d/dL2 - d/dL1, d/dxi2 = d/dL3 - d/dL1
    d1 = dl(:, 2) - dl(:, 1)
    d2 = dl(:, 3) - dl(:, 1)
  end subroutine shape

  !> dx/dxi1 x dx/dxi2 and x at (xi1, xi2) in element e.
  subroutine element_frame(m, e, xi1, xi2, nvec, x)
    type(mesh_t), intent(in) :: m
    integer, intent(in) :: e
    real(dp), intent(in) :: xi1, xi2
    real(dp), intent(out) :: nvec(3), x(3)
    real(dp) :: n(10), d1(10), d2(10), g1(3), g2(3), xe(3, 10)
    call shape(xi1, xi2, n, d1, d2)
    xe = m%x(:, m%conn(:, e))
    x = matmul(xe, n)
    g1 = matmul(xe, d1)
    g2 = matmul(xe, d2)
    nvec = [g1(2)*g2(3) - g1(3)*g2(2), g1(3)*g2(1) - g1(1)*g2(3), g1(1)*g2(2) - g1(2)*g2(1)]
  end subroutine element_frame

  real(dp) function mesh_area(m) result(a)
    type(mesh_t), intent(in) :: m
    real(dp) :: nvec(3), x(3)
    integer :: e, q
    a = 0.0_dp
    do e = 1, m%nelem
      do q = 1, 7
        call element_frame(m, e, qxi(1, q), qxi(2, q), nvec, x)
        a = a + qw(q)*norm2(nvec)
      end do
    end do
  end function mesh_area

  !> Elements whose centroid normal does not point outward (radially / +z).
  integer function count_misoriented(m, surface) result(n)
    type(mesh_t), intent(in) :: m
    character(len=*), intent(in) :: surface
    real(dp) :: nvec(3), x(3), outward(3)
    integer :: e
    n = 0
    do e = 1, m%nelem
      call element_frame(m, e, 1.0_dp/3, 1.0_dp/3, nvec, x)
      select case (surface)
      case ('cylinder')
        outward = [x(1), x(2), 0.0_dp]
      case ('sphere')
        outward = x
      case default
        outward = [0.0_dp, 0.0_dp, 1.0_dp]
      end select
      if (.not. (dot_product(nvec, outward) > 0.0_dp)) n = n + 1
    end do
  end function count_misoriented

  ! ---------------------------------------------------------------------------------------------
  ! Topology (plain O(n^2) searches: small meshes, obviously right)

  integer function count_referenced(m) result(n)
    type(mesh_t), intent(in) :: m
    logical, allocatable :: used(:)
    allocate (used(m%nnode), source=.false.)
    if (minval(m%conn) < 1 .or. maxval(m%conn) > m%nnode) then
      n = -1
      return
    end if
    used(pack(m%conn, .true.)) = .true.
    n = count(used)
  end function count_referenced

  integer function count_corner_nodes(m) result(n)
    type(mesh_t), intent(in) :: m
    logical, allocatable :: used(:)
    allocate (used(m%nnode), source=.false.)
    used(pack(m%conn(1:3, :), .true.)) = .true.
    n = count(used)
  end function count_corner_nodes

  !> Smallest distance between two distinct nodes (0 if a node was not merged).
  real(dp) function min_separation(m) result(d)
    type(mesh_t), intent(in) :: m
    integer :: i, j
    d = huge(1.0_dp)
    do j = 2, m%nnode
      do i = 1, j - 1
        d = min(d, sum((m%x(:, i) - m%x(:, j))**2))
      end do
    end do
    d = sqrt(d)
  end function min_separation

  !> Number of elements having corner nodes a and b on one of their edges (either direction).
  integer function edge_uses(m, a, b) result(n)
    type(mesh_t), intent(in) :: m
    integer, intent(in) :: a, b
    integer, parameter :: ea(3) = [1, 2, 3], eb(3) = [2, 3, 1]
    integer :: e, k, p, q
    n = 0
    do e = 1, m%nelem
      do k = 1, 3
        p = m%conn(ea(k), e)
        q = m%conn(eb(k), e)
        if ((p == a .and. q == b) .or. (p == b .and. q == a)) n = n + 1
      end do
    end do
  end function edge_uses

  !> Number of distinct corner edges used by exactly `times` elements.
  integer function count_edges(m, times) result(n)
    type(mesh_t), intent(in) :: m
    integer, intent(in) :: times
    integer, parameter :: ea(3) = [1, 2, 3], eb(3) = [2, 3, 1]
    integer :: e, k, uses
    real(dp) :: total
    total = 0.0_dp
    do e = 1, m%nelem
      do k = 1, 3
        uses = edge_uses(m, m%conn(ea(k), e), m%conn(eb(k), e))
        ! Each distinct edge is met `uses` times: count 1/uses per meeting.
        if (uses == times) total = total + 1.0_dp/real(uses, dp)
      end do
    end do
    n = nint(total)
  end function count_edges

  !> Directed element edges a->b (with edge nodes p, q from a) lacking exactly one element with
  !> the edge b->a and edge nodes q, p: catches flipped elements and unmerged edge nodes.
  integer function count_unmatched_twins(m) result(n)
    type(mesh_t), intent(in) :: m
    integer, parameter :: ea(3) = [1, 2, 3], eb(3) = [2, 3, 1], ep(3) = [4, 6, 8], eq(3) = [5, 7, 9]
    integer :: e, k, f, j, twins
    n = 0
    do e = 1, m%nelem
      do k = 1, 3
        twins = 0
        do f = 1, m%nelem
          do j = 1, 3
            if (m%conn(ea(j), f) == m%conn(eb(k), e) .and. m%conn(eb(j), f) == m%conn(ea(k), e) .and. &
                m%conn(ep(j), f) == m%conn(eq(k), e) .and. m%conn(eq(j), f) == m%conn(ep(k), e)) twins = twins + 1
          end do
        end do
        if (twins /= 1) n = n + 1
      end do
    end do
  end function count_unmatched_twins

  ! ---------------------------------------------------------------------------------------------
  ! Reporting

  logical function check_ok(name, err) result(ok)
    character(len=*), intent(in) :: name
    type(error_t), allocatable, intent(in) :: err
    ok = .not. allocated(err)
    if (ok) then
      call report(.true., name, 'ok', '')
    else
      call report(.false., name, '"' // err%message // '"', 'no error')
    end if
  end function check_ok

  subroutine check_int(name, value, expected)
    character(len=*), intent(in) :: name
    integer, intent(in) :: value, expected
    character(len=24) :: v, x
    write (v, '(i0)') value
    write (x, '(i0)') expected
    call report(value == expected, name, trim(v), trim(x))
  end subroutine check_int

  !> Pass when 0 <= value <= tol.
  subroutine check_small(name, value, tol)
    character(len=*), intent(in) :: name
    real(dp), intent(in) :: value, tol
    character(len=24) :: v, x
    write (v, '(es10.3)') value
    write (x, '(a,es9.2)') '<=', tol
    call report(value >= 0.0_dp .and. value <= tol, name, trim(adjustl(v)), trim(x))
  end subroutine check_small

  subroutine report(ok, name, value, expected)
    logical, intent(in) :: ok
    character(len=*), intent(in) :: name, value, expected
    if (ok) then
      write (*, '(a)') 'PASS ' // name // ' ' // value
    else
      nfail = nfail + 1
      write (*, '(a)') 'FAIL ' // name // ' ' // value // ' ' // expected
    end if
  end subroutine report
end program test_mesh_io
