!> The rigid obstacles drawn for the frames: each a surface of linear triangles where it is at
!> a time. A plane or a cylinder has no end, so it is drawn about the bodies as they stand: a
!> plane as a square patch centred on the bodies' bounding box's centre projected on it, a
!> cylinder as a tube along the box's extent on its axis, each 1.5 times that extent; a sphere
!> whole. A few hundred triangles each: drawn, not computed with. An `inside` obstacle is the
!> same surface.
module casca_obstacle_surface
  use casca_kinds, only: dp
  use casca_obstacle, only: obstacle_t, unit_across
  use casca_vectors, only: cross
  implicit none
  private
  public :: obstacle_surfaces

  real(dp), parameter :: pi = acos(-1._dp)
  real(dp), parameter :: cover = 1.5_dp     !< a plane's or a tube's extent over the bodies'
  integer, parameter :: plane_cells = 8     !< a plane's squares a side (two triangles each)
  integer, parameter :: around = 32, along = 4   !< a tube's points around, segments along
  integer, parameter :: lat = 10, lon = 20  !< a sphere's bands from pole to pole, points around

contains

  !> The surfaces of obs at time t about the bodies' points x(3, :): the points p(3, :), the
  !> triangles tri(3, :) (1-based, each facing the side a plane's normal points to) and the
  !> obstacle of each triangle, which(:) (its index in obs)
  pure subroutine obstacle_surfaces(obs, t, x, p, tri, which)
    type(obstacle_t), intent(in) :: obs(:)
    real(dp), intent(in) :: t, x(:, :)
    real(dp), allocatable, intent(out) :: p(:, :)
    integer, allocatable, intent(out) :: tri(:, :), which(:)
    real(dp), allocatable :: pk(:, :)
    integer, allocatable :: tk(:, :)
    real(dp) :: lo(3), hi(3), c(3)
    integer :: k
    lo = minval(x, dim=2); hi = maxval(x, dim=2)
    allocate (p(3, 0), tri(3, 0), which(0))
    do k = 1, size(obs)
      c = obs(k)%point + t*obs(k)%velocity
      select case (obs(k)%shape)
      case ('plane')
        call plane_patch(c, obs(k)%normal, lo, hi, pk, tk)
      case ('sphere')
        call sphere_mesh(c, obs(k)%radius, pk, tk)
      case default
        call tube(c, obs(k)%normal, obs(k)%radius, lo, hi, pk, tk)
      end select
      tri = reshape([tri, tk + size(p, 2)], [3, size(tri, 2) + size(tk, 2)])
      p = reshape([p, pk], [3, size(p, 2) + size(pk, 2)])
      which = [which, spread(k, 1, size(tk, 2))]
    end do
  end subroutine obstacle_surfaces

  !> The box [lo, hi]'s extent along the unit vector a
  pure real(dp) function extent(a, lo, hi)
    real(dp), intent(in) :: a(3), lo(3), hi(3)
    extent = sum(abs(a)*(hi - lo))
  end function extent

  !> A square of plane_cells^2 squares in the plane through c of unit normal n, centred on
  !> the box's centre projected on it, its side cover times the box's larger extent in it
  pure subroutine plane_patch(c, n, lo, hi, p, tri)
    real(dp), intent(in) :: c(3), n(3), lo(3), hi(3)
    real(dp), allocatable, intent(out) :: p(:, :)
    integer, allocatable, intent(out) :: tri(:, :)
    real(dp) :: u(3), w(3), o(3), m(3), side
    integer :: i, j
    u = unit_across(n); w = cross(n, u)   ! (u x w = n)
    m = 0.5_dp*(lo + hi)
    o = m - dot_product(m - c, n)*n
    side = cover*max(extent(u, lo, hi), extent(w, lo, hi))
    if (side <= 0) side = cover*norm2(hi - lo)   ! (bodies on one line along n)
    allocate (p(3, (plane_cells + 1)**2))
    do j = 0, plane_cells
      do i = 0, plane_cells
        p(:, 1 + i + (plane_cells + 1)*j) = o + side*((real(i, dp)/plane_cells - 0.5_dp)*u + &
                                                      (real(j, dp)/plane_cells - 0.5_dp)*w)
      end do
    end do
    tri = grid_triangles(plane_cells + 1, plane_cells, .false.)
  end subroutine plane_patch

  !> A tube of radius r about the axis through c along the unit vector a, over cover times
  !> the box's extent along it (at least r), about the box's centre
  pure subroutine tube(c, a, r, lo, hi, p, tri)
    real(dp), intent(in) :: c(3), a(3), r, lo(3), hi(3)
    real(dp), allocatable, intent(out) :: p(:, :)
    integer, allocatable, intent(out) :: tri(:, :)
    real(dp) :: u(3), w(3), mid, length, s, phi
    integer :: i, j
    u = unit_across(a); w = cross(a, u)
    mid = dot_product(0.5_dp*(lo + hi) - c, a)
    length = max(cover*extent(a, lo, hi), r)   ! (a flat ring across the axis has none)
    allocate (p(3, around*(along + 1)))
    do j = 0, along
      s = mid + length*(real(j, dp)/along - 0.5_dp)
      do i = 0, around - 1
        phi = 2*pi*i/around
        p(:, 1 + i + around*j) = c + s*a + r*(cos(phi)*u + sin(phi)*w)
      end do
    end do
    tri = grid_triangles(around, along, .true.)
  end subroutine tube

  !> A sphere of centre c and radius r: lat - 1 rings of lon points and the two poles
  pure subroutine sphere_mesh(c, r, p, tri)
    real(dp), intent(in) :: c(3), r
    real(dp), allocatable, intent(out) :: p(:, :)
    integer, allocatable, intent(out) :: tri(:, :)
    real(dp) :: theta, phi
    integer :: i, j, top, bottom, nt
    integer, allocatable :: bands(:, :)
    allocate (p(3, lon*(lat - 1) + 2))
    do j = 1, lat - 1
      theta = pi*j/lat
      do i = 0, lon - 1
        phi = 2*pi*i/lon
        p(:, 1 + i + lon*(j - 1)) = c + r*[sin(theta)*cos(phi), sin(theta)*sin(phi), cos(theta)]
      end do
    end do
    top = lon*(lat - 1) + 1; bottom = top + 1
    p(:, top) = c + r*[0._dp, 0._dp, 1._dp]
    p(:, bottom) = c - r*[0._dp, 0._dp, 1._dp]
    bands = grid_triangles(lon, lat - 2, .true.)
    nt = size(bands, 2)
    allocate (tri(3, nt + 2*lon))
    tri(:, 1:nt) = bands
    do i = 0, lon - 1   ! (the fans about the poles)
      tri(:, nt + 1 + i) = [top, 1 + mod(i + 1, lon), 1 + i]
      tri(:, nt + lon + 1 + i) = [bottom, 1 + i + lon*(lat - 2), 1 + mod(i + 1, lon) + lon*(lat - 2)]
    end do
  end subroutine sphere_mesh

  !> Two triangles per cell of a grid of rows of m points (point 1 + i + m j), nj cells high;
  !> closed: the last point of a row joins its first (a tube's, a sphere's rings)
  pure function grid_triangles(m, nj, closed) result(tri)
    integer, intent(in) :: m, nj
    logical, intent(in) :: closed
    integer, allocatable :: tri(:, :)
    integer :: i, j, ni, k, a, b
    ni = merge(m, m - 1, closed)
    allocate (tri(3, 2*ni*nj))
    k = 0
    do j = 0, nj - 1
      do i = 0, ni - 1
        a = 1 + i + m*j; b = 1 + mod(i + 1, m) + m*j
        tri(:, k + 1) = [a, b, b + m]
        tri(:, k + 2) = [a, b + m, a + m]
        k = k + 2
      end do
    end do
  end function grid_triangles
end module casca_obstacle_surface
