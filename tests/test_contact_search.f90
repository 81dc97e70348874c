!> Contact search: closest point on a triangle against hand-computed answers and brute force;
!> the grid search against the thesis' all-pairs scan (same sub-triangle, same distance bit for
!> bit); parent coordinates of sub-triangle points; timing of both searches (printed only).
program test_contact_search
  use, intrinsic :: iso_fortran_env, only: int64
  use casca_kinds, only: dp
  use casca_error, only: error_t
  use casca_mesh, only: mesh_t
  use casca_mesh_generators, only: mesh_ring, mesh_sphere
  use casca_shape_tri10, only: tri10_shape, tri10_node_xi, subtri10
  use casca_closest_point, only: closest_point_triangle, region_face, region_edge_ab, &
      region_edge_bc, region_edge_ca, region_vertex_a, region_vertex_b, region_vertex_c
  use casca_surface_search, only: surface_t, grid_t, surface_init, grid_build, &
      nearest_subtriangle, nearest_all_pairs, surface_box, subtri_parent_xi
  implicit none

  integer :: npass = 0, nfail = 0

  call seed_rng()
  call test_hand_cases()
  call test_degenerate()
  call test_brute_force()
  call test_random_cloud()
  call test_rings()
  call test_restricted_grid()
  call test_parent_xi()
  call timing()

  print '(i0,a,i0,a)', npass, ' passed, ', nfail, ' failed'
  if (nfail > 0) error stop 1

contains

  ! ---------------------------------------------------------------- helpers

  subroutine check(name, ok, value)
    character(len=*), intent(in) :: name
    logical, intent(in) :: ok
    real(dp), intent(in) :: value
    if (ok) then
      npass = npass + 1
      print '(a,a,1x,es12.4)', 'PASS ', name, value
    else
      nfail = nfail + 1
      print '(a,a,1x,es12.4)', 'FAIL ', name, value
    end if
  end subroutine check

  subroutine seed_rng()
    integer :: n, i
    integer, allocatable :: seed(:)
    call random_seed(size=n)
    allocate (seed(n))
    seed = [(104729 + 7919*i, i=1, n)]
    call random_seed(put=seed)
  end subroutine seed_rng

  function rand3() result(r)
    real(dp) :: r(3)
    call random_number(r)
  end function rand3

  !> Uniform point of triangle (a, b, c) by folding the unit square.
  function sample_tri(a, b, c) result(s)
    real(dp), intent(in) :: a(3), b(3), c(3)
    real(dp) :: s(3), r(2)
    call random_number(r)
    if (r(1) + r(2) > 1.0_dp) r = 1.0_dp - r
    s = a + r(1)*(b - a) + r(2)*(c - a)
  end function sample_tri

  !> Rotation by angles (z, y, x), an orthonormal matrix to move the hand cases off the axes.
  function rotation(az, ay, ax) result(r)
    real(dp), intent(in) :: az, ay, ax
    real(dp) :: r(3, 3), rz(3, 3), ry(3, 3), rx(3, 3)
    rz = reshape([cos(az), sin(az), 0.0_dp, -sin(az), cos(az), 0.0_dp, 0.0_dp, 0.0_dp, 1.0_dp], [3, 3])
    ry = reshape([cos(ay), 0.0_dp, -sin(ay), 0.0_dp, 1.0_dp, 0.0_dp, sin(ay), 0.0_dp, cos(ay)], [3, 3])
    rx = reshape([1.0_dp, 0.0_dp, 0.0_dp, 0.0_dp, cos(ax), sin(ax), 0.0_dp, -sin(ax), cos(ax)], [3, 3])
    r = matmul(rz, matmul(ry, rx))
  end function rotation

  ! ---------------------------------------------------------------- closest point

  !> Triangle (0,0,0),(1,0,0),(0,1,0): two points (above/below the plane) in each of the 7
  !> regions, closest points from elementary geometry; then the same cases rotated + shifted.
  subroutine test_hand_cases()
    integer, parameter :: nc = 14
    real(dp) :: p(3, nc), qe(3, nc), a(3), b(3), c(3), q(3), bary(3), r(3, 3), sh(3), err, errr
    integer :: re(nc), region, i
    character(len=12), parameter :: label(nc) = [character(len=12) :: &
        'face+', 'face-', 'edge_ab+', 'edge_ab-', 'edge_bc+', 'edge_bc-', 'edge_ca+', 'edge_ca-', &
        'vertex_a+', 'vertex_a-', 'vertex_b+', 'vertex_b-', 'vertex_c+', 'vertex_c-']

    a = [0.0_dp, 0.0_dp, 0.0_dp]
    b = [1.0_dp, 0.0_dp, 0.0_dp]
    c = [0.0_dp, 1.0_dp, 0.0_dp]
    ! face: the foot of the perpendicular
    p(:, 1) = [0.2_dp, 0.2_dp, 0.5_dp];    qe(:, 1) = [0.2_dp, 0.2_dp, 0.0_dp];   re(1) = region_face
    p(:, 2) = [0.2_dp, 0.2_dp, -0.5_dp];   qe(:, 2) = [0.2_dp, 0.2_dp, 0.0_dp];   re(2) = region_face
    ! edge a-b (y = 0): drop y and z
    p(:, 3) = [0.5_dp, -0.3_dp, 0.1_dp];   qe(:, 3) = [0.5_dp, 0.0_dp, 0.0_dp];   re(3) = region_edge_ab
    p(:, 4) = [0.3_dp, -0.2_dp, -0.4_dp];  qe(:, 4) = [0.3_dp, 0.0_dp, 0.0_dp];   re(4) = region_edge_ab
    ! edge b-c (x + y = 1): t = ((p - b).(-1, 1))/2 from b
    p(:, 5) = [0.8_dp, 0.6_dp, 0.2_dp];    qe(:, 5) = [0.6_dp, 0.4_dp, 0.0_dp];   re(5) = region_edge_bc
    p(:, 6) = [0.6_dp, 0.7_dp, -0.3_dp];   qe(:, 6) = [0.45_dp, 0.55_dp, 0.0_dp]; re(6) = region_edge_bc
    ! edge c-a (x = 0): drop x and z
    p(:, 7) = [-0.4_dp, 0.3_dp, 0.2_dp];   qe(:, 7) = [0.0_dp, 0.3_dp, 0.0_dp];   re(7) = region_edge_ca
    p(:, 8) = [-0.1_dp, 0.75_dp, -0.2_dp]; qe(:, 8) = [0.0_dp, 0.75_dp, 0.0_dp];  re(8) = region_edge_ca
    ! vertices: p - v has a non-positive component along both edges leaving v
    p(:, 9) = [-0.3_dp, -0.2_dp, 0.1_dp];  qe(:, 9) = a;  re(9) = region_vertex_a
    p(:, 10) = [-0.1_dp, -0.5_dp, -0.3_dp]; qe(:, 10) = a; re(10) = region_vertex_a
    p(:, 11) = [1.4_dp, -0.2_dp, 0.3_dp];  qe(:, 11) = b; re(11) = region_vertex_b
    p(:, 12) = [1.2_dp, 0.1_dp, -0.2_dp];  qe(:, 12) = b; re(12) = region_vertex_b
    p(:, 13) = [-0.2_dp, 1.3_dp, 0.4_dp];  qe(:, 13) = c; re(13) = region_vertex_c
    p(:, 14) = [0.1_dp, 1.4_dp, -0.1_dp];  qe(:, 14) = c; re(14) = region_vertex_c

    r = rotation(0.7_dp, -0.4_dp, 1.9_dp)
    sh = [3.0_dp, -2.0_dp, 0.5_dp]
    do i = 1, nc
      call closest_point_triangle(p(:, i), a, b, c, q, bary, region)
      err = max(maxval(abs(q - qe(:, i))), maxval(abs(bary(1)*a + bary(2)*b + bary(3)*c - q)))
      call check('closest_point '//trim(label(i)), region == re(i) .and. err <= 1.0e-15_dp, err)
      ! Rigid motion of triangle and point: same region, moved closest point.
      call closest_point_triangle(matmul(r, p(:, i)) + sh, matmul(r, a) + sh, matmul(r, b) + sh, &
                                  matmul(r, c) + sh, q, bary, region)
      errr = maxval(abs(q - (matmul(r, qe(:, i)) + sh)))
      call check('closest_point rotated '//trim(label(i)), region == re(i) .and. errr <= 1.0e-14_dp, errr)
    end do
    ! Order of the vertices matters only for the labels: (b, c, a) relabels edge a-b as c-a.
    call closest_point_triangle(p(:, 3), b, c, a, q, bary, region)
    err = maxval(abs(q - qe(:, 3)))
    call check('closest_point relabelled edge', region == region_edge_ca .and. err <= 1.0e-15_dp, err)
  end subroutine test_hand_cases

  !> Zero-area triangles: the answer of the segments, finite.
  subroutine test_degenerate()
    real(dp), parameter :: hs(7) = [0.0_dp, 1.0e-300_dp, 1.0e-12_dp, 1.0e-9_dp, 1.0e-7_dp, 1.0e-4_dp, 0.1_dp]
    real(dp) :: q(3), bary(3), o(3), e(3), c(3), p(3), worst, dmin
    integer :: region, ih, ip, k
    logical :: ok

    o = [0.0_dp, 0.0_dp, 0.0_dp]
    e = [1.0_dp, 0.0_dp, 0.0_dp]
    ! collinear a, b, c = 0, 1, 2 on the x axis: nearest point of the x-segment [0, 2]
    call closest_point_triangle([1.5_dp, 1.0_dp, 0.0_dp], o, e, 2*e, q, bary, region)
    ok = region == region_edge_bc .and. all(abs(q - [1.5_dp, 0.0_dp, 0.0_dp]) <= 1.0e-15_dp) &
         .and. all(q == q) .and. all(bary >= 0.0_dp)
    call check('degenerate collinear', ok, abs(q(1) - 1.5_dp))
    ! a = b: segment a-c
    call closest_point_triangle([0.3_dp, 2.0_dp, 1.0_dp], o, o, [0.0_dp, 1.0_dp, 0.0_dp], q, bary, region)
    ok = region == region_vertex_c .and. all(abs(q - [0.0_dp, 1.0_dp, 0.0_dp]) <= 1.0e-15_dp) .and. all(q == q)
    call check('degenerate a=b vertex', ok, maxval(abs(q - [0.0_dp, 1.0_dp, 0.0_dp])))
    ! (segments b-c and c-a coincide; the first of equal candidates, b-c, is kept)
    call closest_point_triangle([0.3_dp, 0.5_dp, 1.0_dp], o, o, [0.0_dp, 1.0_dp, 0.0_dp], q, bary, region)
    ok = region == region_edge_bc .and. all(abs(q - [0.0_dp, 0.5_dp, 0.0_dp]) <= 1.0e-15_dp) .and. all(q == q)
    call check('degenerate a=b edge', ok, maxval(abs(q - [0.0_dp, 0.5_dp, 0.0_dp])))
    ! a = b = c
    call closest_point_triangle([0.3_dp, 0.5_dp, 1.0_dp], e, e, e, q, bary, region)
    ok = all(q == e) .and. abs(sum(bary) - 1.0_dp) <= 0.0_dp
    call check('degenerate point', ok, maxval(abs(q - e)))

    ! Slivers of height hs (both sides of the segment / face switch at hs ~ 1e-8): finite
    ! answers, bary valid, and no farther than the sampled points by more than hs.
    worst = -huge(1.0_dp)
    ok = .true.
    do ih = 1, size(hs)
      do ip = 1, 300
        p = 2.0_dp*rand3() - 0.5_dp
        p(3) = 0.2_dp*p(3)
        c = [0.3_dp, hs(ih), 0.0_dp]
        call closest_point_triangle(p, o, e, c, q, bary, region)
        ok = ok .and. all(q == q) .and. all(bary >= 0.0_dp) .and. abs(sum(bary) - 1.0_dp) <= 1.0e-15_dp &
             .and. maxval(abs(bary(1)*o + bary(2)*e + bary(3)*c - q)) <= 1.0e-15_dp
        dmin = huge(1.0_dp)
        do k = 1, 500
          dmin = min(dmin, norm2(p - sample_tri(o, e, c)))
        end do
        dmin = min(dmin, norm2(p - o), norm2(p - e), norm2(p - c))
        worst = max(worst, norm2(p - q) - dmin - hs(ih))
      end do
    end do
    call check('slivers: finite, valid bary, dist <= sampled + height', ok .and. worst <= 1.0e-12_dp, worst)
  end subroutine test_degenerate

  !> Random points and triangles: the returned distance never exceeds that of 2,000 sampled
  !> points of the triangle (plus its vertices); bary reproduces q; p - q is orthogonal to the
  !> face / edge it lies in; the region agrees with the zero pattern of bary.
  subroutine test_brute_force()
    integer, parameter :: npt = 10000, nsamp = 2000, per_tri = 500
    real(dp) :: a(3), b(3), c(3), s(3, nsamp + 3), p(3), q(3), bary(3), dmin, d
    real(dp) :: worst_excess, worst_bary, worst_orth, u(3)
    integer :: ip, k, region, nlabel
    logical :: label_ok

    worst_excess = -huge(1.0_dp)
    worst_bary = 0.0_dp
    worst_orth = 0.0_dp
    nlabel = 0
    a = [0.0_dp, 0.0_dp, 0.0_dp]; b = [1.0_dp, 0.0_dp, 0.0_dp]; c = [0.0_dp, 1.0_dp, 0.0_dp]
    do ip = 1, npt
      ! first batch on the reference triangle, then a new random triangle every per_tri points
      if (ip == 1 .or. (ip > npt/2 .and. mod(ip, per_tri) == 1)) then
        if (ip > 1) then
          a = rand3(); b = rand3(); c = rand3()
        end if
        do k = 1, nsamp
          s(:, k) = sample_tri(a, b, c)
        end do
        s(:, nsamp + 1) = a; s(:, nsamp + 2) = b; s(:, nsamp + 3) = c
      end if
      p = 3.0_dp*rand3() - 1.0_dp
      call closest_point_triangle(p, a, b, c, q, bary, region)
      d = norm2(p - q)
      dmin = huge(1.0_dp)
      do k = 1, nsamp + 3
        dmin = min(dmin, (p(1) - s(1, k))**2 + (p(2) - s(2, k))**2 + (p(3) - s(3, k))**2)
      end do
      worst_excess = max(worst_excess, d - sqrt(dmin))
      worst_bary = max(worst_bary, maxval(abs(bary(1)*a + bary(2)*b + bary(3)*c - q)), &
                       abs(sum(bary) - 1.0_dp), -minval(bary))
      ! First-order optimality: p - q is normal to what q lies in.
      u = p - q
      select case (region)
      case (region_face)
        worst_orth = max(worst_orth, abs(dot_product(u, b - a)), abs(dot_product(u, c - a)))
        label_ok = all(bary > 0.0_dp)
      case (region_edge_ab)
        worst_orth = max(worst_orth, abs(dot_product(u, b - a)))
        label_ok = bary(3) == 0.0_dp .and. bary(1) > 0.0_dp .and. bary(2) > 0.0_dp
      case (region_edge_bc)
        worst_orth = max(worst_orth, abs(dot_product(u, c - b)))
        label_ok = bary(1) == 0.0_dp .and. bary(2) > 0.0_dp .and. bary(3) > 0.0_dp
      case (region_edge_ca)
        worst_orth = max(worst_orth, abs(dot_product(u, a - c)))
        label_ok = bary(2) == 0.0_dp .and. bary(1) > 0.0_dp .and. bary(3) > 0.0_dp
      case (region_vertex_a)
        label_ok = all(q == a)
      case (region_vertex_b)
        label_ok = all(q == b)
      case (region_vertex_c)
        label_ok = all(q == c)
      case default
        label_ok = .false.
      end select
      if (.not. label_ok) nlabel = nlabel + 1
    end do
    call check('brute force: dist - min sampled dist <= 1e-12', worst_excess <= 1.0e-12_dp, worst_excess)
    call check('brute force: bary reproduces q, >= 0, sums to 1', worst_bary <= 1.0e-14_dp, worst_bary)
    call check('brute force: p - q normal to face/edge', worst_orth <= 1.0e-13_dp, worst_orth)
    call check('brute force: region agrees with bary', nlabel == 0, real(nlabel, dp))
  end subroutine test_brute_force

  ! ---------------------------------------------------------------- grid vs all pairs

  !> Compare the two searches on points pts(3, :); returns the number of mismatches (itri,
  !> found, dist bitwise, q, region) and counts how many were found.
  subroutine compare_searches(surf, grid, x, pts, rmax, nbad, nfound)
    type(surface_t), intent(in) :: surf
    type(grid_t), intent(inout) :: grid
    real(dp), intent(in) :: x(:, :), pts(:, :), rmax
    integer, intent(out) :: nbad, nfound
    logical :: f1, f2
    integer :: i1, i2, r1, r2, ip
    real(dp) :: q1(3), q2(3), b1(3), b2(3), d1, d2

    nbad = 0
    nfound = 0
    do ip = 1, size(pts, 2)
      call nearest_subtriangle(surf, grid, x, pts(:, ip), rmax, f1, i1, q1, b1, d1, r1)
      call nearest_all_pairs(surf, x, pts(:, ip), rmax, f2, i2, q2, b2, d2, r2)
      if (f2) nfound = nfound + 1
      if (f1 .neqv. f2) then
        nbad = nbad + 1
      else if (f1) then
        if (i1 /= i2 .or. .not. (d1 == d2) .or. any(q1 /= q2) .or. any(b1 /= b2) .or. r1 /= r2) nbad = nbad + 1
      end if
    end do
  end subroutine compare_searches

  !> A grid built only over the sub-triangles that meet a box (the impactor's, grown by the
  !> band) answers exactly as the all-pairs scan of the whole surface for every point whose
  !> rmax-ball lies in that box.
  subroutine test_restricted_grid()
    type(mesh_t) :: mesh
    type(error_t), allocatable :: err
    type(surface_t) :: surf
    type(grid_t) :: grid
    real(dp), parameter :: rmax = 0.05_dp
    real(dp) :: within(3, 2), pts(3, 5000), r(3)
    integer :: ip, nbad, nfound
    call mesh_sphere(1.0_dp, 6, mesh, err)
    if (allocated(err)) then
      call check('restricted grid: sphere mesh', .false., 0.0_dp); return
    end if
    call surface_init(mesh%conn, [(ip, ip=1, mesh%nelem)], surf)
    within(:, 1) = [0.6_dp, -0.5_dp, -0.5_dp]; within(:, 2) = [1.2_dp, 0.5_dp, 0.5_dp]
    call grid_build(surf, mesh%x, grid, within)
    do ip = 1, size(pts, 2)   ! points in the box shrunk by rmax, half of them near the surface
      pts(:, ip) = within(:, 1) + rmax + (within(:, 2) - within(:, 1) - 2*rmax)*rand3()
      r = rand3()
      if (mod(ip, 2) == 0) pts(1, ip) = sqrt(max(0.0_dp, 1 - pts(2, ip)**2 - pts(3, ip)**2)) &
                                        + 0.04_dp*(2*r(1) - 1)
    end do
    call compare_searches(surf, grid, mesh%x, pts, rmax, nbad, nfound)
    call check('restricted grid == all pairs within rmax, points in the box (mismatches)', &
               nbad == 0 .and. nfound > 1000, real(nbad, dp))
  end subroutine test_restricted_grid

  !> 300 cubic elements with random node coordinates: clusters of small elements, a few
  !> elements spanning the cloud, and a few degenerate ones (coincident / collinear nodes).
  subroutine test_random_cloud()
    integer, parameter :: ne = 300, npt = 20000
    real(dp), allocatable :: x(:, :), pts(:, :)
    integer, allocatable :: conn(:, :), elems(:)
    type(surface_t) :: surf
    type(grid_t) :: grid
    real(dp) :: centre(3), box(3, 2)
    integer :: e, k, nbad, nfound, it
    logical :: ok

    allocate (x(3, 10*ne), conn(10, ne), pts(3, npt))
    do e = 1, ne
      centre = 8.0_dp*rand3()
      do k = 1, 10
        conn(k, e) = 10*(e - 1) + k
        if (e <= 8) then
          x(:, conn(k, e)) = 8.0_dp*rand3()                        ! spans the cloud
        else if (e <= 11) then
          x(:, conn(k, e)) = centre                                ! a point
        else if (e <= 14) then
          x(:, conn(k, e)) = centre + rand3()*[1.0_dp, 0.0_dp, 0.0_dp]   ! on a line
        else
          x(:, conn(k, e)) = centre + 0.8_dp*(rand3() - 0.5_dp)
        end if
      end do
    end do
    ! The surface is every other element, listed backwards: elems(:) need not be 1..n.
    allocate (elems(ne/2))
    elems = [(ne - 2*(k - 1), k=1, ne/2)]
    call surface_init(conn, elems, surf)
    ok = surf%ntri == 9*size(elems)
    do it = 1, surf%ntri
      e = elems((it - 1)/9 + 1)
      k = mod(it - 1, 9) + 1
      ok = ok .and. surf%elem(it) == e .and. surf%sub(it) == k .and. all(surf%tri(:, it) == conn(subtri10(:, k), e))
    end do
    call check('surface_init: 9 sub-triangles per element, in order', ok, real(surf%ntri, dp))
    ! The sub-triangles use all ten nodes of each element: the box is that of the elements' nodes.
    box = surface_box(surf, x)
    ok = .true.
    do k = 1, 3
      ok = ok .and. box(k, 1) == minval([(minval(x(k, conn(:, elems(e)))), e=1, size(elems))]) &
              .and. box(k, 2) == maxval([(maxval(x(k, conn(:, elems(e)))), e=1, size(elems))])
    end do
    call check('surface_box: corners of the surface elements'' nodes', ok, box(1, 2) - box(1, 1))

    call grid_build(surf, x, grid)
    do k = 1, npt
      pts(:, k) = 10.0_dp*rand3() - 1.0_dp    ! in and around the cloud [0, 8]^3
    end do
    ! Some points exactly on sub-triangle vertices and far outside the box.
    do k = 1, 200
      pts(:, k) = x(:, surf%tri(1 + mod(k, 3), 1 + mod(37*k, surf%ntri)))
      pts(:, 200 + k) = 40.0_dp*rand3() - 20.0_dp
    end do
    call compare_searches(surf, grid, x, pts(:, 1:npt/2), huge(1.0_dp), nbad, nfound)
    call check('random cloud, rmax=huge: grid == all pairs (mismatches)', nbad == 0 .and. nfound == npt/2, &
               real(nbad, dp))
    call compare_searches(surf, grid, x, pts(:, npt/2 + 1:), 0.3_dp, nbad, nfound)
    call check('random cloud, rmax=0.3: grid == all pairs (mismatches)', nbad == 0 .and. nfound > 0 &
               .and. nfound < npt/2, real(nbad, dp))
    print '(a,i0,a,i0)', 'INFO random cloud rmax=0.3: found ', nfound, ' of ', npt/2

    ! Move the nodes and rebuild into the same grid object (the Newton-iteration use).
    x = x + 0.5_dp*(spread(rand3(), 2, size(x, 2)) - 0.5_dp) + 0.05_dp*sin(3.0_dp*x)
    call grid_build(surf, x, grid)
    call compare_searches(surf, grid, x, pts(:, 1:2000), huge(1.0_dp), nbad, nfound)
    call check('random cloud moved + rebuilt: grid == all pairs', nbad == 0, real(nbad, dp))
  end subroutine test_random_cloud

  !> Two rings (radius 1, width 0.2, 20 x 1 cubic elements), the second shifted by (2.01,0,0):
  !> they come within 0.01 of each other at x = 1.005.
  subroutine test_rings()
    type(mesh_t) :: ring
    type(error_t), allocatable :: err
    type(surface_t) :: surf1, surf2
    type(grid_t) :: grid1, grid2
    real(dp), allocatable :: x(:, :), pts(:, :)
    integer, allocatable :: conn(:, :)
    real(dp) :: q(3), bary(3), dist, dmin, r, th
    integer :: nn, ne, k, nbad, nfound, itri, region, ip
    logical :: found

    call mesh_ring(1.0_dp, 0.2_dp, 20, 1, ring, err)
    if (allocated(err)) then
      call check('mesh_ring: '//err%message, .false., 0.0_dp)
      return
    end if
    nn = ring%nnode
    ne = ring%nelem
    allocate (x(3, 2*nn), conn(10, 2*ne))
    x(:, 1:nn) = ring%x
    x(:, nn + 1:) = ring%x + spread([2.01_dp, 0.0_dp, 0.0_dp], 2, nn)
    conn(:, 1:ne) = ring%conn
    conn(:, ne + 1:) = ring%conn + nn
    call surface_init(conn, [(k, k=1, ne)], surf1)
    call surface_init(conn, [(k, k=ne + 1, 2*ne)], surf2)
    call grid_build(surf1, x, grid1)
    call grid_build(surf2, x, grid2)

    call compare_searches(surf1, grid1, x, x(:, nn + 1:), huge(1.0_dp), nbad, nfound)
    call check('ring: nodes of ring 2 vs ring 1, rmax=huge', nbad == 0 .and. nfound == nn, real(nbad, dp))
    call compare_searches(surf1, grid1, x, x(:, nn + 1:), 0.1_dp, nbad, nfound)
    call check('ring: nodes of ring 2 vs ring 1, rmax=0.1', nbad == 0 .and. nfound > 0, real(nbad, dp))
    call compare_searches(surf2, grid2, x, x(:, 1:nn), huge(1.0_dp), nbad, nfound)
    call check('ring: nodes of ring 1 vs ring 2, rmax=huge', nbad == 0 .and. nfound == nn, real(nbad, dp))

    ! Independent answer: the closest node pairs are (1, 0, z) and (1.01, 0, z): gap 0.01.
    dmin = huge(1.0_dp)
    do k = nn + 1, 2*nn
      call nearest_subtriangle(surf1, grid1, x, x(:, k), huge(1.0_dp), found, itri, q, bary, dist, region)
      dmin = min(dmin, dist)
    end do
    call check('ring: smallest node gap = 0.01', abs(dmin - 0.01_dp) <= 1.0e-12_dp, dmin)
    ! A node of ring 2 at its far side (3.01, 0, z): nearest is ring 1's node (1, 0, z), 2.01 away.
    call nearest_subtriangle(surf1, grid1, x, [3.01_dp, 0.0_dp, 0.1_dp], huge(1.0_dp), found, itri, q, bary, &
                             dist, region)
    call check('ring: far point distance 2.01', found .and. abs(dist - 2.01_dp) <= 1.0e-12_dp, dist)
    call nearest_subtriangle(surf1, grid1, x, [3.01_dp, 0.0_dp, 0.1_dp], 2.0_dp, found, itri, q, bary, &
                             dist, region)
    call check('ring: far point beyond rmax=2 not found', .not. found, dist)

    ! Random points near ring 1 (annulus, both sides) and in a wide box around it.
    allocate (pts(3, 6000))
    do ip = 1, 5000
      call random_number(r)
      call random_number(th)
      th = 6.283185307179586_dp*th
      r = 0.85_dp + 0.3_dp*r
      pts(:, ip) = [r*cos(th), r*sin(th), 0.0_dp]
      call random_number(pts(3, ip))
      pts(3, ip) = 0.4_dp*pts(3, ip) - 0.2_dp
    end do
    do ip = 5001, 6000
      pts(:, ip) = 8.0_dp*rand3() - 4.0_dp
    end do
    call compare_searches(surf1, grid1, x, pts, huge(1.0_dp), nbad, nfound)
    call check('ring: random points near and around, rmax=huge', nbad == 0, real(nbad, dp))
    call compare_searches(surf1, grid1, x, pts, 0.05_dp, nbad, nfound)
    call check('ring: random points near and around, rmax=0.05', nbad == 0 .and. nfound > 0, real(nbad, dp))
    ! Every sub-triangle lies in a vertical plane through a chord of the 60-gon of nodes, so
    ! it lies between the radii cos(pi/60) and 1: distance >= r - 1 outside the cylinder and
    ! >= cos(pi/60) - r inside the chords.
    dmin = -huge(1.0_dp)
    do ip = 1, 5000
      call nearest_subtriangle(surf1, grid1, x, pts(:, ip), huge(1.0_dp), found, itri, q, bary, dist, region)
      r = norm2(pts(1:2, ip))
      dmin = max(dmin, r - 1.0_dp - dist, cos(3.141592653589793_dp/60) - r - dist)
    end do
    call check('ring: dist >= radial gap to the cylinder / inscribed prism', dmin <= 1.0e-12_dp, dmin)
  end subroutine test_rings

  !> Parent coordinates: sub-triangle corners are lattice nodes; on a flat element whose nodes
  !> are an affine image of the lattice, the cubic map of xi reproduces the closest point.
  subroutine test_parent_xi()
    type(surface_t) :: surf
    real(dp) :: xe(3, 10), o(3), t1(3), t2(3), xi(2), phi(10), dphi(10, 2), p(3), q(3), bary(3)
    real(dp) :: err, dist, errmap
    integer :: s, k, l, itri, region, ip
    integer :: conn(10, 1)
    logical :: found

    o = [0.3_dp, -1.2_dp, 2.0_dp]
    t1 = [1.3_dp, 0.4_dp, -0.5_dp]
    t2 = [-0.2_dp, 0.9_dp, 0.7_dp]
    do l = 1, 10
      xe(:, l) = o + tri10_node_xi(1, l)*t1 + tri10_node_xi(2, l)*t2
      conn(l, 1) = l
    end do
    call surface_init(conn, [1], surf)

    err = 0.0_dp
    do s = 1, 9
      do k = 1, 3
        bary = 0.0_dp
        bary(k) = 1.0_dp
        call subtri_parent_xi(surf, s, bary, xi)
        err = max(err, maxval(abs(xi - tri10_node_xi(:, subtri10(k, s)))))
      end do
    end do
    call check('subtri_parent_xi: corners are the lattice nodes', err == 0.0_dp, err)

    errmap = 0.0_dp
    do ip = 1, 2000
      p = o + 1.6_dp*(rand3() - 0.3_dp)
      call nearest_all_pairs(surf, xe, p, huge(1.0_dp), found, itri, q, bary, dist, region)
      call subtri_parent_xi(surf, itri, bary, xi)
      call tri10_shape(xi(1), xi(2), phi, dphi)
      errmap = max(errmap, maxval(abs(matmul(xe, phi) - q)))
    end do
    call check('subtri_parent_xi: flat cubic map of xi reproduces q', errmap <= 1.0e-13_dp, errmap)
  end subroutine test_parent_xi

  ! ---------------------------------------------------------------- timing

  subroutine timing()
    type(mesh_t) :: mesh
    type(error_t), allocatable :: err
    call mesh_ring(1.0_dp, 0.2_dp, 20, 1, mesh, err)
    if (.not. allocated(err)) call time_case('ring 20x1', mesh, 20000, 5000)
    call mesh_sphere(1.0_dp, 6, mesh, err)
    if (.not. allocated(err)) call time_case('sphere n_div=6', mesh, 20000, 500)
  end subroutine timing

  !> Queries per second for points within 0.1 of the surface (nodes in mesh order plus a random
  !> offset, as impactor nodes would come); the timed answers of both searches are compared too.
  subroutine time_case(name, mesh, ngrid, npairs)
    character(len=*), intent(in) :: name
    type(mesh_t), intent(in) :: mesh
    integer, intent(in) :: ngrid, npairs
    type(surface_t) :: surf
    type(grid_t) :: grid
    real(dp), allocatable :: pts(:, :), dgrid(:), dpairs(:)
    integer, allocatable :: igrid(:), ipairs(:)
    real(dp) :: q(3), bary(3), tg, ta, tb, qps_grid, qps_pairs
    integer :: ip, region, ib, nbad
    integer(int64) :: t0, t1, rate
    logical :: found

    call surface_init(mesh%conn, [(ip, ip=1, mesh%nelem)], surf)
    allocate (pts(3, ngrid), dgrid(ngrid), igrid(ngrid), dpairs(npairs), ipairs(npairs))
    do ip = 1, ngrid
      pts(:, ip) = mesh%x(:, 1 + mod(ip - 1, mesh%nnode)) + 0.2_dp*(rand3() - 0.5_dp)
    end do
    call system_clock(t0, rate)
    do ib = 1, 10
      call grid_build(surf, mesh%x, grid)
    end do
    call system_clock(t1)
    tb = real(t1 - t0, dp)/real(rate, dp)/10

    call system_clock(t0)
    do ip = 1, ngrid
      call nearest_subtriangle(surf, grid, mesh%x, pts(:, ip), huge(1.0_dp), found, igrid(ip), q, bary, &
                               dgrid(ip), region)
    end do
    call system_clock(t1)
    tg = max(real(t1 - t0, dp)/real(rate, dp), 1.0e-9_dp)
    call system_clock(t0)
    do ip = 1, npairs
      call nearest_all_pairs(surf, mesh%x, pts(:, ip), huge(1.0_dp), found, ipairs(ip), q, bary, &
                             dpairs(ip), region)
    end do
    call system_clock(t1)
    ta = max(real(t1 - t0, dp)/real(rate, dp), 1.0e-9_dp)
    qps_grid = ngrid/tg
    qps_pairs = npairs/ta
    print '(a,a,a,i0,a,es9.2,a,es9.2,a,es9.2,a,f7.1)', 'TIME ', name, ': ntri ', surf%ntri, &
        '  grid_build ', tb, ' s  grid ', qps_grid, ' q/s  all-pairs ', qps_pairs, ' q/s  speed-up ', &
        qps_grid/qps_pairs
    nbad = count(igrid(1:npairs) /= ipairs .or. .not. (dgrid(1:npairs) == dpairs))
    call check('timing case '//name//': grid == all pairs', nbad == 0, real(nbad, dp))
  end subroutine time_case
end program test_contact_search
