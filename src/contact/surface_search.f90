!> Nearest sub-triangle of a target surface to a point (contact detection, formulation.md
!> section 3). The target is the set of linear sub-triangles of its cubic elements; the thesis
!> compares every node with every sub-triangle (nearest_all_pairs). nearest_subtriangle gets
!> the same answer from a uniform bucket grid: it visits shells of cells around the point and
!> stops as soon as nothing unvisited can beat (or tie with) the best candidate, so it returns
!> exactly the sub-triangle the all-pairs scan returns.
!>
!> Both routines rank candidates by the distance computed by the same private kernel
!> (eval_subtri), ties broken by the smaller sub-triangle number. The grid only skips a
!> sub-triangle when a lower bound of its distance (its bounding box, or the cells not yet
!> visited) exceeds the best distance by a margin tol ~ 1e-10 x coordinate size. That bound is
!> valid for the *computed* distance whatever the kernel's accuracy, because the computed q is
!> a convex combination of the vertices and so lies in the box up to a few ulps; the margin
!> covers those ulps and the rounding of the cell faces. Hence the two answers agree bit for bit.
module casca_surface_search
  use casca_kinds, only: dp
  use casca_shape_tri10, only: tri10_node_xi, subtri10
  use casca_closest_point, only: closest_point_triangle
  use casca_orientation, only: vertex_elements
  implicit none
  private
  public :: surface_t, grid_t
  public :: surface_init, grid_build, nearest_subtriangle, nearest_all_pairs
  public :: surface_box, subtri_parent_xi

  !> The linear sub-triangles of a set of cubic elements.
  type :: surface_t
    integer :: ntri = 0
    integer, allocatable :: tri(:, :)   !< (3, ntri) global node numbers of each sub-triangle
    integer, allocatable :: elem(:)     !< (ntri) parent element (global element number)
    integer, allocatable :: sub(:)      !< (ntri) 1..9: which sub-triangle of subtri10
    !> (3, ntri) edge ab, bc, ca (the region_edge_* order) on the surface's rim: no other
    !> sub-triangle shares it (an open surface's boundary)
    logical, allocatable :: rim(:, :)
    !> (3, ntri) vertex a, b, c on a rim edge
    logical, allocatable :: rim_vertex(:, :)
  end type surface_t

  !> Bucket grid over the sub-triangles' bounding boxes at the positions of the last
  !> grid_build. Cell (i, j, k), 0-based, is [lo + (i, j, k) h, lo + (i+1, j+1, k+1) h]; its
  !> entries are cell_start(id) : cell_start(id+1) - 1, id = 1 + i + n1 (j + n2 k), each a
  !> sub-triangle number and a copy of its box (so the box pre-test reads memory in order).
  type :: grid_t
    private
    integer :: ntri = -1                   ! sub-triangles binned; -1 before the first build
    integer :: n(3) = 1                    ! cells per direction
    real(dp) :: lo(3) = 0.0_dp, hi(3) = 0.0_dp
    real(dp) :: h(3) = 0.0_dp, invh(3) = 0.0_dp   ! cell size, and its inverse (0 if flat)
    real(dp) :: scale = 0.0_dp             ! coordinate magnitude, for the rounding margin
    integer, allocatable :: cell_start(:)  ! (ncell + 1); capacity may exceed
    integer, allocatable :: entry_tri(:)   ! (nentry) sub-triangle; capacity may exceed
    real(dp), allocatable :: entry_box(:, :)  ! (6, nentry) its box: min corner, max corner
    integer, allocatable :: stamp(:)       ! (ntri) last query that evaluated the sub-triangle
    integer, allocatable :: kept(:)        ! sub-triangles binned at the last build
    real(dp), allocatable :: kept_box(:, :)   ! (6, ntri) their boxes: min corner, max corner
    integer :: query = 0
  end type grid_t

  !> Cell count cap per sub-triangle (memory), and the relative rounding margin of the bounds:
  !> far above the kernel's rounding (a few ulps of the coordinates), far below any distance
  !> that matters, so it only makes the search visit a few more cells.
  integer, parameter :: cells_per_tri = 4, cells_extra = 64
  real(dp), parameter :: margin_rel = 1.0e-10_dp
  !> Squares of numbers above this would overflow: such bounds are treated as infinite.
  real(dp), parameter :: big = 1.0e150_dp

contains

  !> Sub-triangles of the elements elems(:) (9 per element, element by element, in subtri10
  !> order); conn(10, :) is the global connectivity of all elements.
  subroutine surface_init(conn, elems, surf)
    integer, intent(in) :: conn(:, :), elems(:)
    type(surface_t), intent(out) :: surf
    integer :: ie, s, it

    surf%ntri = 9*size(elems)
    allocate (surf%tri(3, surf%ntri), surf%elem(surf%ntri), surf%sub(surf%ntri))
    it = 0
    do ie = 1, size(elems)
      do s = 1, 9
        it = it + 1
        surf%tri(:, it) = conn(subtri10(:, s), elems(ie))
        surf%elem(it) = elems(ie)
        surf%sub(it) = s
      end do
    end do
    call find_rim(surf)
  end subroutine surface_init

  !> The rim: the sub-triangle edges no other sub-triangle shares, found through the
  !> sub-triangles at each vertex (as casca_orientation's edge census), and the vertices on them.
  subroutine find_rim(surf)
    type(surface_t), intent(inout) :: surf
    integer, allocatable :: start(:), at(:)
    logical, allocatable :: on_rim(:)
    integer :: it, k, a, b, j
    call vertex_elements(surf%tri, maxval(surf%tri), start, at)
    allocate (surf%rim(3, surf%ntri), surf%rim_vertex(3, surf%ntri), on_rim(maxval(surf%tri)))
    on_rim = .false.
    do it = 1, surf%ntri
      do k = 1, 3
        a = surf%tri(k, it); b = surf%tri(mod(k, 3) + 1, it)
        surf%rim(k, it) = .true.
        do j = start(a), start(a + 1) - 1
          if (at(j) /= it .and. any(surf%tri(:, at(j)) == b)) surf%rim(k, it) = .false.
        end do
        if (surf%rim(k, it)) on_rim([a, b]) = .true.
      end do
    end do
    do it = 1, surf%ntri
      surf%rim_vertex(:, it) = on_rim(surf%tri(:, it))
    end do
  end subroutine find_rim

  !> (Re)bin the sub-triangles at the current coordinates x(3, nnode). O(ntri + cells); the
  !> arrays are reused when large enough, since this runs every Newton iteration. With
  !> within(:, 1:2) (min and max corner) only the sub-triangles whose box meets it are binned:
  !> nearest_subtriangle is then exact for the points whose rmax-ball lies inside that box
  !> (the impactor's box grown by the band: the few target elements it can touch).
  subroutine grid_build(surf, x, grid, within)
    type(surface_t), intent(in) :: surf
    real(dp), intent(in) :: x(:, :)
    type(grid_t), intent(inout) :: grid
    real(dp), intent(in), optional :: within(3, 2)
    real(dp) :: ext(3), hcell, cap, ncell_r, nd(3), blo(3), bhi(3)
    integer :: it, k, ncell, nentry, id, iter, nkept

    grid%ntri = surf%ntri
    if (allocated(grid%stamp)) then
      if (size(grid%stamp) /= surf%ntri) deallocate (grid%stamp)
    end if
    if (.not. allocated(grid%stamp)) allocate (grid%stamp(surf%ntri))
    grid%stamp = 0
    grid%query = 0

    ! Box of the surface and mean sub-triangle size.
    grid%lo = huge(1.0_dp)
    grid%hi = -huge(1.0_dp)
    ! The kept sub-triangles and their boxes, once: both binning passes read them.
    hcell = 0.0_dp
    nkept = 0
    call ensure_int(grid%kept, surf%ntri)
    call ensure_real6(grid%kept_box, surf%ntri)
    do it = 1, surf%ntri
      call tri_box(surf, x, it, blo, bhi)
      if (present(within)) then
        if (any(blo > within(:, 2)) .or. any(bhi < within(:, 1))) cycle
      end if
      nkept = nkept + 1
      grid%kept(nkept) = it
      grid%kept_box(1:3, nkept) = blo; grid%kept_box(4:6, nkept) = bhi
      grid%lo = min(grid%lo, blo)
      grid%hi = max(grid%hi, bhi)
      hcell = hcell + maxval(bhi - blo)
    end do
    if (nkept == 0) then
      grid%lo = 0.0_dp
      grid%hi = 0.0_dp
    end if
    ext = grid%hi - grid%lo
    grid%scale = maxval(max(abs(grid%lo), abs(grid%hi))) + maxval(ext)

    ! Cell size = mean sub-triangle size (a sub-triangle then touches a few cells and a cell
    ! holds a few sub-triangles), enlarged if the cell count would exceed the cap.
    if (nkept > 0) hcell = hcell/real(nkept, dp)
    if (.not. (hcell > 0.0_dp)) hcell = max(maxval(ext), 1.0_dp)
    cap = real(cells_per_tri*nkept + cells_extra, dp)
    do iter = 1, 100
      do k = 1, 3
        nd(k) = max(1.0_dp, real(ceiling(min(ext(k)/hcell, cap)), dp))
      end do
      ncell_r = nd(1)*nd(2)*nd(3)
      if (ncell_r <= cap) exit
      hcell = hcell*max((ncell_r/cap)**(1.0_dp/3.0_dp), 1.01_dp)
    end do
    if (ncell_r > cap) nd = 1.0_dp   ! not reached: the loop shrinks the count geometrically
    grid%n = nint(nd)
    do k = 1, 3
      if (ext(k) > 0.0_dp) then
        grid%h(k) = ext(k)/real(grid%n(k), dp)
        grid%invh(k) = real(grid%n(k), dp)/ext(k)
      else
        grid%n(k) = 1
        grid%h(k) = 0.0_dp
        grid%invh(k) = 0.0_dp
      end if
    end do
    ncell = grid%n(1)*grid%n(2)*grid%n(3)
    call ensure_int(grid%cell_start, ncell + 1)

    ! Counting sort of (cell, sub-triangle) pairs into CSR: count, prefix sum, fill.
    grid%cell_start(1:ncell + 1) = 0
    nentry = 0
    call bin(.false.)
    grid%cell_start(1) = 1
    do id = 1, ncell
      grid%cell_start(id + 1) = grid%cell_start(id + 1) + grid%cell_start(id)
    end do
    call ensure_int(grid%entry_tri, nentry)
    call ensure_real6(grid%entry_box, nentry)
    ! cell_start(id) serves as the insertion cursor, then everything is shifted back by one.
    call bin(.true.)
    do id = ncell, 1, -1
      grid%cell_start(id + 1) = grid%cell_start(id)
    end do
    grid%cell_start(1) = 1
  contains
    !> visit every (cell, kept sub-triangle) pair: count per cell, or fill the entries
    subroutine bin(fill)
      logical, intent(in) :: fill
      integer :: m, i, j, l, i0(3), i1(3), pos
      do m = 1, nkept
        call cell_range(grid, grid%kept_box(1:3, m), grid%kept_box(4:6, m), i0, i1)
        do l = i0(3), i1(3)
          do j = i0(2), i1(2)
            do i = i0(1), i1(1)
              id = cell_id(grid, i, j, l)
              if (fill) then
                pos = grid%cell_start(id)
                grid%entry_tri(pos) = grid%kept(m)
                grid%entry_box(:, pos) = grid%kept_box(:, m)
                grid%cell_start(id) = pos + 1
              else
                grid%cell_start(id + 1) = grid%cell_start(id + 1) + 1
              end if
            end do
          end do
        end do
        if (.not. fill) nentry = nentry + product(i1 - i0 + 1)
      end do
    end subroutine bin
  end subroutine grid_build

  !> Nearest sub-triangle to p among those at distance <= rmax (found = .false. if none), the
  !> same itri, q, bary, dist and region as nearest_all_pairs. x must be the coordinates the
  !> grid was built with. grid is inout only for its visited stamps.
  !> With ref, pref and rskip (self-contact), the sub-triangles with a vertex whose position in
  !> ref lies within rskip of pref are left out.
  subroutine nearest_subtriangle(surf, grid, x, p, rmax, found, itri, q, bary, dist, region, &
                                 ref, pref, rskip)
    type(surface_t), intent(in) :: surf
    type(grid_t), intent(inout) :: grid
    real(dp), intent(in) :: x(:, :), p(3), rmax
    logical, intent(out) :: found
    integer, intent(out) :: itri, region
    real(dp), intent(out) :: q(3), bary(3), dist
    real(dp), intent(in), optional :: ref(:, :), pref(3), rskip
    real(dp) :: tol, g(3), t, gsum, bound, f, e, lim2
    integer :: c(3), lo(3), hi(3), k, i, j, l, d

    call clear_result(found, itri, q, bary, dist, region)
    if (surf%ntri == 0) return
    if (grid%ntri /= surf%ntri) then   ! grid not built for this surface: be right, if slow
      call nearest_all_pairs(surf, x, p, rmax, found, itri, q, bary, dist, region)
      return
    end if

    tol = margin_rel*(grid%scale + maxval(abs(p)))
    ! p's cell (clamped into the grid) and p's distance to the grid box, per direction.
    do d = 1, 3
      t = (p(d) - grid%lo(d))*grid%invh(d)
      t = min(max(t, 0.0_dp), real(grid%n(d) - 1, dp))
      c(d) = int(t)
      g(d) = min(max(grid%lo(d) - p(d), p(d) - grid%hi(d), 0.0_dp), big)
    end do
    gsum = g(1)**2 + g(2)**2 + g(3)**2
    if (sqrt(gsum) > rmax + tol) return

    if (grid%query == huge(grid%query)) then
      grid%stamp = 0
      grid%query = 0
    end if
    grid%query = grid%query + 1

    lim2 = square_limit(rmax + tol)
    do k = 0, maxval(grid%n)
      lo = max(c - k, 0)
      hi = min(c + k, grid%n - 1)
      ! The cells of Chebyshev distance exactly k from c (within the grid).
      do j = lo(2), hi(2)
        do i = lo(1), hi(1)
          if (abs(i - c(1)) == k .or. abs(j - c(2)) == k) then
            do l = lo(3), hi(3)
              call scan_cell(surf, grid, x, p, rmax, tol, cell_id(grid, i, j, l), lim2, &
                             found, itri, q, bary, dist, region, ref, pref, rskip)
            end do
          else
            if (c(3) - k >= 0) call scan_cell(surf, grid, x, p, rmax, tol, cell_id(grid, i, j, c(3) - k), &
                                              lim2, found, itri, q, bary, dist, region, ref, pref, rskip)
            if (c(3) + k <= grid%n(3) - 1) call scan_cell(surf, grid, x, p, rmax, tol, &
                cell_id(grid, i, j, c(3) + k), lim2, found, itri, q, bary, dist, region, ref, pref, rskip)
          end if
        end do
      end do

      ! Lower bound on the distance to any unvisited cell: such a cell lies in the grid box
      ! beyond one face of the visited block, so its gap is the face gap in that direction and
      ! at least the box gap in the other two.
      bound = huge(1.0_dp)
      do d = 1, 3
        e = max(gsum - g(d)**2, 0.0_dp)
        if (c(d) - k > 0) then
          f = min(max(p(d) - (grid%lo(d) + real(c(d) - k, dp)*grid%h(d)), 0.0_dp), big)
          bound = min(bound, sqrt(e + f*f))
        end if
        if (c(d) + k < grid%n(d) - 1) then
          f = min(max((grid%lo(d) + real(c(d) + k + 1, dp)*grid%h(d)) - p(d), 0.0_dp), big)
          bound = min(bound, sqrt(e + f*f))
        end if
      end do
      if (bound == huge(1.0_dp)) exit            ! every cell visited
      if (found .and. dist + tol < bound) exit   ! nothing unvisited can reach or tie
      if (bound > rmax + tol) exit               ! nothing unvisited is within rmax
    end do
  end subroutine nearest_subtriangle

  !> Examine the entries of cell cid: box pre-test (the box distance is a lower bound of the
  !> sub-triangle's), then each sub-triangle once per query; keep the best (ties: smaller itri).
  !> lim2 = (min(dist, rmax) + tol)^2 is the pre-test's limit.
  subroutine scan_cell(surf, grid, x, p, rmax, tol, cid, lim2, found, itri, q, bary, dist, region, &
                       ref, pref, rskip)
    type(surface_t), intent(in) :: surf
    type(grid_t), intent(inout) :: grid
    real(dp), intent(in) :: x(:, :), p(3), rmax, tol
    integer, intent(in) :: cid
    real(dp), intent(inout) :: lim2
    logical, intent(inout) :: found
    integer, intent(inout) :: itri, region
    real(dp), intent(inout) :: q(3), bary(3), dist
    real(dp), intent(in), optional :: ref(:, :), pref(3), rskip
    real(dp) :: qt(3), bt(3), dt, bd2
    integer :: pos, it, reg

    do pos = grid%cell_start(cid), grid%cell_start(cid + 1) - 1
      bd2 = max(grid%entry_box(1, pos) - p(1), p(1) - grid%entry_box(4, pos), 0.0_dp)**2 &
          + max(grid%entry_box(2, pos) - p(2), p(2) - grid%entry_box(5, pos), 0.0_dp)**2 &
          + max(grid%entry_box(3, pos) - p(3), p(3) - grid%entry_box(6, pos), 0.0_dp)**2
      if (bd2 > lim2) cycle
      it = grid%entry_tri(pos)
      if (grid%stamp(it) == grid%query) cycle
      grid%stamp(it) = grid%query
      if (present(rskip)) then
        if (any([norm2(ref(:, surf%tri(1, it)) - pref), norm2(ref(:, surf%tri(2, it)) - pref), &
                 norm2(ref(:, surf%tri(3, it)) - pref)] < rskip)) cycle
      end if
      call eval_subtri(surf, x, it, p, qt, bt, dt, reg)
      if (dt > rmax) cycle
      if (found) then
        if (.not. (dt < dist .or. (dt == dist .and. it < itri))) cycle
      end if
      found = .true.
      itri = it
      q = qt
      bary = bt
      dist = dt
      region = reg
      lim2 = square_limit(dist + tol)
    end do
  end subroutine scan_cell

  !> r^2, or huge when that would overflow (an unbounded limit).
  pure real(dp) function square_limit(r)
    real(dp), intent(in) :: r
    if (r < big) then
      square_limit = r*r
    else
      square_limit = huge(1.0_dp)
    end if
  end function square_limit

  !> The thesis' search: every sub-triangle; nearest within rmax, ties to the smaller itri.
  pure subroutine nearest_all_pairs(surf, x, p, rmax, found, itri, q, bary, dist, region)
    type(surface_t), intent(in) :: surf
    real(dp), intent(in) :: x(:, :), p(3), rmax
    logical, intent(out) :: found
    integer, intent(out) :: itri, region
    real(dp), intent(out) :: q(3), bary(3), dist
    real(dp) :: qt(3), bt(3), dt
    integer :: it, reg

    call clear_result(found, itri, q, bary, dist, region)
    do it = 1, surf%ntri
      call eval_subtri(surf, x, it, p, qt, bt, dt, reg)
      if (dt > rmax) cycle
      if (found) then
        if (.not. dt < dist) cycle   ! ascending itri: an equal distance keeps the earlier one
      end if
      found = .true.
      itri = it
      q = qt
      bary = bt
      dist = dt
      region = reg
    end do
  end subroutine nearest_all_pairs

  !> (3, 2): min and max corner of the surface's nodes at x (zeros for an empty surface).
  pure function surface_box(surf, x) result(box)
    type(surface_t), intent(in) :: surf
    real(dp), intent(in) :: x(:, :)
    real(dp) :: box(3, 2)
    integer :: it, k

    if (surf%ntri == 0) then
      box = 0.0_dp
      return
    end if
    box(:, 1) = huge(1.0_dp)
    box(:, 2) = -huge(1.0_dp)
    do it = 1, surf%ntri
      do k = 1, 3
        box(:, 1) = min(box(:, 1), x(:, surf%tri(k, it)))
        box(:, 2) = max(box(:, 2), x(:, surf%tri(k, it)))
      end do
    end do
  end function surface_box

  !> Parent-element coordinates (xi1, xi2) of the point with barycentric bary on sub-triangle
  !> itri: the sub-triangle is linear in xi as well, with its corners at lattice nodes.
  pure subroutine subtri_parent_xi(surf, itri, bary, xi)
    type(surface_t), intent(in) :: surf
    integer, intent(in) :: itri
    real(dp), intent(in) :: bary(3)
    real(dp), intent(out) :: xi(2)
    integer :: s

    s = surf%sub(itri)
    xi = bary(1)*tri10_node_xi(:, subtri10(1, s)) + bary(2)*tri10_node_xi(:, subtri10(2, s)) &
       + bary(3)*tri10_node_xi(:, subtri10(3, s))
  end subroutine subtri_parent_xi

  ! ---------------------------------------------------------------------------------------

  !> The one distance kernel both searches rank by (so they agree bit for bit).
  pure subroutine eval_subtri(surf, x, it, p, q, bary, dist, region)
    type(surface_t), intent(in) :: surf
    real(dp), intent(in) :: x(:, :), p(3)
    integer, intent(in) :: it
    real(dp), intent(out) :: q(3), bary(3), dist
    integer, intent(out) :: region
    real(dp) :: a(3), b(3), c(3)
    integer :: ia, ib, ic

    ! Local copies, written out (x may be strided; no packing temporaries, no copy loops).
    ia = surf%tri(1, it)
    ib = surf%tri(2, it)
    ic = surf%tri(3, it)
    a(1) = x(1, ia); a(2) = x(2, ia); a(3) = x(3, ia)
    b(1) = x(1, ib); b(2) = x(2, ib); b(3) = x(3, ib)
    c(1) = x(1, ic); c(2) = x(2, ic); c(3) = x(3, ic)
    call closest_point_triangle(p, a, b, c, q, bary, region)
    dist = sqrt((p(1) - q(1))**2 + (p(2) - q(2))**2 + (p(3) - q(3))**2)
  end subroutine eval_subtri

  pure subroutine clear_result(found, itri, q, bary, dist, region)
    logical, intent(out) :: found
    integer, intent(out) :: itri, region
    real(dp), intent(out) :: q(3), bary(3), dist
    found = .false.
    itri = 0
    region = -1
    q = 0.0_dp
    bary = 0.0_dp
    dist = huge(1.0_dp)
  end subroutine clear_result

  !> Bounding box of sub-triangle it.
  pure subroutine tri_box(surf, x, it, blo, bhi)
    type(surface_t), intent(in) :: surf
    real(dp), intent(in) :: x(:, :)
    integer, intent(in) :: it
    real(dp), intent(out) :: blo(3), bhi(3)
    integer :: k
    do k = 1, 3
      blo(k) = min(x(k, surf%tri(1, it)), x(k, surf%tri(2, it)), x(k, surf%tri(3, it)))
      bhi(k) = max(x(k, surf%tri(1, it)), x(k, surf%tri(2, it)), x(k, surf%tri(3, it)))
    end do
  end subroutine tri_box

  !> Cell index range (0-based, clamped into the grid) covered by the box [blo, bhi].
  pure subroutine cell_range(grid, blo, bhi, i0, i1)
    type(grid_t), intent(in) :: grid
    real(dp), intent(in) :: blo(3), bhi(3)
    integer, intent(out) :: i0(3), i1(3)
    integer :: d
    do d = 1, 3
      i0(d) = cell_of(grid, d, blo(d))
      i1(d) = cell_of(grid, d, bhi(d))
    end do
  end subroutine cell_range

  pure integer function cell_of(grid, d, v)
    type(grid_t), intent(in) :: grid
    integer, intent(in) :: d
    real(dp), intent(in) :: v
    real(dp) :: t
    t = (v - grid%lo(d))*grid%invh(d)
    cell_of = int(min(max(t, 0.0_dp), real(grid%n(d) - 1, dp)))
  end function cell_of

  pure integer function cell_id(grid, i, j, l)
    type(grid_t), intent(in) :: grid
    integer, intent(in) :: i, j, l
    cell_id = 1 + i + grid%n(1)*(j + grid%n(2)*l)
  end function cell_id

  !> Make a at least n long (contents not kept).
  subroutine ensure_int(a, n)
    integer, allocatable, intent(inout) :: a(:)
    integer, intent(in) :: n
    if (allocated(a)) then
      if (size(a) >= n) return
      deallocate (a)
    end if
    allocate (a(max(n, 1)))
  end subroutine ensure_int

  !> Make a at least (6, n) (contents not kept).
  subroutine ensure_real6(a, n)
    real(dp), allocatable, intent(inout) :: a(:, :)
    integer, intent(in) :: n
    if (allocated(a)) then
      if (size(a, 2) >= n) return
      deallocate (a)
    end if
    allocate (a(6, max(n, 1)))
  end subroutine ensure_real6
end module casca_surface_search
