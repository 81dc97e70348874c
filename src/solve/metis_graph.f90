!> The two uses of METIS: the element partition over MPI ranks (dual graph of the mesh), and
!> a nested-dissection ordering of the unknowns handed to MUMPS (Debian's MUMPS is built
!> without METIS, so ICNTL(7) = 5 would silently fall back).
module casca_metis
  use, intrinsic :: iso_c_binding, only: c_int, c_ptr, c_null_ptr
  use casca_error, only: error_t, fatal_error
  implicit none
  private
  public :: partition_elements, nested_dissection

  integer(c_int), parameter :: metis_ok = 1, metis_noptions = 40

  interface
    integer(c_int) function metis_partmeshdual(ne, nn, eptr, eind, vwgt, vsize, ncommon, &
        nparts, tpwgts, options, objval, epart, npart) bind(c, name='METIS_PartMeshDual')
      import :: c_int, c_ptr
      integer(c_int), intent(in) :: ne, nn, ncommon, nparts
      integer(c_int), intent(in) :: eptr(*), eind(*)
      type(c_ptr), value :: vwgt, vsize, tpwgts
      integer(c_int), intent(in) :: options(*)
      integer(c_int), intent(out) :: objval, epart(*), npart(*)
    end function metis_partmeshdual
    integer(c_int) function metis_nodend(nvtxs, xadj, adjncy, vwgt, options, perm, iperm) &
        bind(c, name='METIS_NodeND')
      import :: c_int, c_ptr
      integer(c_int), intent(in) :: nvtxs, xadj(*), adjncy(*)
      type(c_ptr), value :: vwgt
      integer(c_int), intent(in) :: options(*)
      integer(c_int), intent(out) :: perm(*), iperm(*)
    end function metis_nodend
    integer(c_int) function metis_setdefaultoptions(options) &
        bind(c, name='METIS_SetDefaultOptions')
      import :: c_int
      integer(c_int), intent(out) :: options(*)
    end function metis_setdefaultoptions
  end interface

contains

  !> owner(e) in 0..nparts-1 for every element of conn(:, nelem) (1-based node numbers).
  subroutine partition_elements(conn, nnode, nparts, owner, err)
    integer, intent(in) :: conn(:, :), nnode, nparts
    integer, intent(out) :: owner(:)
    type(error_t), allocatable, intent(out) :: err
    integer(c_int), allocatable :: eptr(:), eind(:), epart(:), npart(:)
    integer(c_int) :: options(metis_noptions), objval, status
    integer :: ne, e

    ne = size(conn, 2)
    if (nparts <= 1 .or. ne < 2*nparts) then
      ! too few elements to split: round robin keeps every rank busy
      owner = [(mod(e - 1, max(nparts, 1)), e=1, ne)]
      return
    end if
    ! METIS sees only the 3 vertices of each element: two elements sharing an edge share 2
    allocate (eptr(ne + 1), eind(3*ne), epart(ne), npart(nnode))
    eptr = [(3*e, e=0, ne)]
    eind = reshape(conn(1:3, :) - 1, [3*ne])
    status = metis_setdefaultoptions(options)   ! numbering from 0 is METIS's default
    status = metis_partmeshdual(int(ne, c_int), int(nnode, c_int), eptr, eind, c_null_ptr, &
                                c_null_ptr, 2_c_int, int(nparts, c_int), c_null_ptr, options, &
                                objval, epart, npart)
    if (status /= metis_ok) then
      call fatal_error(err, 'METIS_PartMeshDual failed')
      return
    end if
    owner = epart
  end subroutine partition_elements

  !> Pivot position of every equation (MUMPS PERM_IN): METIS nested dissection of the node
  !> graph (nodes sharing an element are neighbours), each node's free equations kept together.
  !> eq(7*(i-1)+c) = equation of component c of node i, 0 if prescribed.
  subroutine nested_dissection(conn, nnode, eq, neq, perm, err)
    integer, intent(in) :: conn(:, :), nnode, eq(:), neq
    integer, intent(out) :: perm(:)
    type(error_t), allocatable, intent(out) :: err
    integer, allocatable :: deg(:), xadj(:), adj(:), mark(:), nperm(:), niperm(:), fill(:)
    integer(c_int) :: options(metis_noptions), status
    integer :: e, a, b, i, k, nen, pos

    nen = size(conn, 1)
    ! node adjacency (CSR without duplicates): count, then fill, with a marker per node
    allocate (deg(nnode), mark(nnode), xadj(nnode + 1))
    deg = 0; mark = 0
    call walk(.false.)
    xadj(1) = 0
    do i = 1, nnode
      xadj(i + 1) = xadj(i) + deg(i)
    end do
    allocate (adj(xadj(nnode + 1)), fill(nnode))
    fill = 0; mark = 0
    call walk(.true.)
    allocate (nperm(nnode), niperm(nnode))
    status = metis_setdefaultoptions(options)   ! numbering from 0 is METIS's default
    status = metis_nodend(int(nnode, c_int), xadj, adj, c_null_ptr, options, nperm, niperm)
    if (status /= metis_ok) then
      call fatal_error(err, 'METIS_NodeND failed')
      return
    end if
    pos = 0
    do k = 1, nnode   ! nperm(k) (0-based) is the node eliminated k-th
      i = nperm(k) + 1
      do a = 1, 7
        if (eq(7*(i - 1) + a) > 0) then
          pos = pos + 1; perm(eq(7*(i - 1) + a)) = pos
        end if
      end do
    end do
    if (pos /= neq) call fatal_error(err, 'nested dissection: equation count mismatch')
  contains
    !> visit each element's node pairs once per node (mark(b) = a avoids repeats)
    subroutine walk(store)
      logical, intent(in) :: store
      integer, allocatable :: start(:), list(:)
      integer :: n, j, m
      ! node -> elements incidence, so that each node's neighbours are gathered at once
      allocate (start(nnode + 1), list(size(conn)))
      start = 0
      do e = 1, size(conn, 2)
        do j = 1, nen
          start(conn(j, e) + 1) = start(conn(j, e) + 1) + 1
        end do
      end do
      start(1) = 1
      do n = 1, nnode
        start(n + 1) = start(n + 1) + start(n)
      end do
      block
        integer, allocatable :: cur(:)
        cur = start(1:nnode)
        do e = 1, size(conn, 2)
          do j = 1, nen
            list(cur(conn(j, e))) = e; cur(conn(j, e)) = cur(conn(j, e)) + 1
          end do
        end do
      end block
      do a = 1, nnode
        do m = start(a), start(a + 1) - 1
          e = list(m)
          do j = 1, nen
            b = conn(j, e)
            if (b == a .or. mark(b) == a) cycle
            mark(b) = a
            if (store) then
              fill(a) = fill(a) + 1; adj(xadj(a) + fill(a)) = b - 1
            else
              deg(a) = deg(a) + 1
            end if
          end do
        end do
      end do
    end subroutine walk
  end subroutine nested_dissection
end module casca_metis
