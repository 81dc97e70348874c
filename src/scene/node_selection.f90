!> Nodes a deck group selects (&restraint, &load): a node list within a body, a named set (a
!> physical group of the body's mesh file) or a box of initial positions (within a body, or
!> over every body); the consistent nodal shares of a uniform line load on the boundary
!> edges of a selection; and the elements a selection covers (a surface load's). Messages name the group and say what was asked; the caller adds the
!> deck's file and line.
module casca_node_selection
  use casca_kinds, only: dp
  use casca_error, only: error_t, fatal_error
  use casca_mesh, only: node_set_t
  use casca_model, only: model_t
  use casca_quadrature, only: gauss_rule
  use casca_strings, only: itoa
  implicit none
  private
  public :: body_sets_t, select_nodes, edge_shares, selected_elements

  !> the named sets of one body, in the body's own node numbering
  type :: body_sets_t
    type(node_set_t), allocatable :: sets(:)
  end type body_sets_t

  !> the three edges of a 10-node triangle, each as its 4 nodes in order along it
  integer, parameter :: edge_nodes(4, 3) = reshape([1, 4, 5, 2, 2, 6, 7, 3, 3, 8, 9, 1], [4, 3])

contains

  !> The model's numbers of the nodes selected by group (for messages, e.g. '&load') in body
  !> (its name; '' for any body): the node list if given, else the set if named, else the
  !> nodes inside the box lo..hi. sets(ib): body ib's sets. An empty selection is an error.
  subroutine select_nodes(model, sets, group, body, nodes, set, lo, hi, sel, err)
    type(model_t), intent(in) :: model
    type(body_sets_t), intent(in) :: sets(:)
    character(len=*), intent(in) :: group, body, set
    integer, intent(in) :: nodes(:)
    real(dp), intent(in) :: lo(3), hi(3)
    integer, allocatable, intent(out) :: sel(:)
    type(error_t), allocatable, intent(out) :: err
    integer :: kb, k, n, first
    character(len=:), allocatable :: names
    logical, allocatable :: mask(:)

    allocate (sel(0))
    kb = 0
    if (body /= '') kb = findloc([(model%body(k)%name == body, k=1, model%nbody)], .true., dim=1)
    if (kb > 0) first = model%body(kb)%node_first
    if (size(nodes) > 0) then
      n = model%body(kb)%node_last - first + 1
      do k = 1, size(nodes)
        if (nodes(k) < 1 .or. nodes(k) > n) then
          call fatal_error(err, group//': nodes('//itoa(k)//') = '//itoa(nodes(k))// &
                           ' is out of range 1..'//itoa(n)//' of body '''//trim(body)//'''')
          return
        end if
      end do
      sel = nodes + first - 1
    else if (set /= '') then
      do k = 1, size(sets(kb)%sets)
        if (sets(kb)%sets(k)%name == trim(set)) then
          sel = sets(kb)%sets(k)%nodes + first - 1
          return
        end if
      end do
      names = ''
      do k = 1, size(sets(kb)%sets)
        names = names//merge(', ', '  ', k > 1)//sets(kb)%sets(k)%name
      end do
      if (names == '') then
        names = 'none'
      else
        names = names(3:)
      end if
      call fatal_error(err, group//': set '''//trim(set)//''' is not a physical group of body '''// &
                       trim(body)//''' (its groups: '//names//')')
    else
      allocate (mask(model%nnode))
      do k = 1, model%nnode
        mask(k) = all(model%x0(:, k) >= lo) .and. all(model%x0(:, k) <= hi)
      end do
      if (kb > 0) mask = mask .and. model%node_body == kb
      sel = pack([(k, k=1, model%nnode)], mask)
      if (size(sel) == 0) then
        if (body == '') then
          call fatal_error(err, group//': no node of any body lies inside box_min..box_max')
        else
          call fatal_error(err, group//': no node of body '''//trim(body)// &
                           ''' lies inside box_min..box_max')
        end if
      end if
    end if
  end subroutine select_nodes

  !> Shares w(k) of a total force carried by node sel(k) as a uniform traction per unit length
  !> of the boundary edges whose 4 nodes are all selected (an edge of one triangle only): the
  !> consistent nodal forces, integral of the cubic Lagrange function of each edge node along
  !> the edge over the total length (1/8, 3/8, 3/8, 1/8 of an edge's share on a straight edge
  !> with its nodes at thirds). sum(w) = 1. No such edge is an error.
  subroutine edge_shares(model, group, sel, w, err)
    type(model_t), intent(in) :: model
    character(len=*), intent(in) :: group
    integer, intent(in) :: sel(:)
    real(dp), allocatable, intent(out) :: w(:)
    type(error_t), allocatable, intent(out) :: err
    integer, allocatable :: pos(:), cand(:, :), start(:), list(:), lo(:), hi(:)
    real(dp), allocatable :: z(:), gw(:)
    real(dp) :: s, n(4), dn(4), dx(3), x(3, 4), total
    integer :: e, j, k, m, nc, nb, en(4), a
    type(error_t), allocatable :: qerr

    allocate (w(size(sel)))
    w = 0
    allocate (pos(model%nnode))
    pos = 0
    pos(sel) = [(k, k=1, size(sel))]
    ! the edges with all 4 nodes selected (element, edge); an inner one is there twice, once
    ! from each of its triangles: bucketed by the lower end node to find the pairs
    allocate (cand(2, 3*model%nelem))
    nc = 0
    do e = 1, model%nelem
      do j = 1, 3
        if (any(pos(model%conn(edge_nodes(:, j), e)) == 0)) cycle
        nc = nc + 1
        cand(:, nc) = [e, j]
      end do
    end do
    allocate (lo(nc), hi(nc))   ! each candidate's end nodes, low and high
    do k = 1, nc
      en = model%conn(edge_nodes(:, cand(2, k)), cand(1, k))
      lo(k) = min(en(1), en(4)); hi(k) = max(en(1), en(4))
    end do
    allocate (start(model%nnode + 1), list(nc))
    start = 0
    do k = 1, nc
      a = lo(k)
      start(a + 1) = start(a + 1) + 1
    end do
    start(1) = 1
    do k = 1, model%nnode
      start(k + 1) = start(k + 1) + start(k)
    end do
    block
      integer :: fill(model%nnode)
      fill = start(1:model%nnode)
      do k = 1, nc
        a = lo(k)
        list(fill(a)) = k
        fill(a) = fill(a) + 1
      end do
    end block
    call gauss_rule(3, z, gw, qerr)
    nb = 0
    do k = 1, nc
      a = lo(k)
      if (count(hi(list(start(a):start(a + 1) - 1)) == hi(k)) > 1) cycle
      nb = nb + 1
      en = model%conn(edge_nodes(:, cand(2, k)), cand(1, k))
      x = model%x0(:, en)
      do m = 1, size(z)
        s = (z(m) + 1)/2
        call lagrange4(s, n, dn)
        dx = matmul(x, dn)
        ! (gw/2: the rule is on [-1, 1], the edge parameter on [0, 1])
        w(pos(en)) = w(pos(en)) + n*norm2(dx)*gw(m)/2
      end do
    end do
    total = sum(w)
    if (nb == 0 .or. total <= 0) then
      call fatal_error(err, group//': kind = ''edge'' needs a boundary edge with its 4 nodes '// &
                       'selected; the selection holds none')
      return
    end if
    w = w/total
  end subroutine edge_shares

  !> The elements whose 10 nodes are all in sel (a surface load's elements). None is an error.
  subroutine selected_elements(model, group, sel, elems, err)
    type(model_t), intent(in) :: model
    character(len=*), intent(in) :: group
    integer, intent(in) :: sel(:)
    integer, allocatable, intent(out) :: elems(:)
    type(error_t), allocatable, intent(out) :: err
    logical :: in(model%nnode)
    integer :: e
    in = .false.
    in(sel) = .true.
    elems = pack([(e, e=1, model%nelem)], [(all(in(model%conn(:, e))), e=1, model%nelem)])
    if (size(elems) == 0) call fatal_error(err, group//': kind = ''pressure'' needs an element '// &
                                           'with its 10 nodes selected; the selection holds none')
  end subroutine selected_elements

  !> Cubic Lagrange functions (and their derivatives) of nodes at s = 0, 1/3, 2/3, 1.
  pure subroutine lagrange4(s, n, dn)
    real(dp), intent(in) :: s
    real(dp), intent(out) :: n(4), dn(4)
    real(dp), parameter :: p(4) = [0._dp, 1._dp/3, 2._dp/3, 1._dp]
    integer :: i, j, k
    real(dp) :: d, t
    do i = 1, 4
      n(i) = 1; dn(i) = 0; d = 1
      do j = 1, 4
        if (j == i) cycle
        d = d*(p(i) - p(j))
        n(i) = n(i)*(s - p(j))
        t = 1
        do k = 1, 4
          if (k /= i .and. k /= j) t = t*(s - p(k))
        end do
        dn(i) = dn(i) + t
      end do
      n(i) = n(i)/d; dn(i) = dn(i)/d
    end do
  end subroutine lagrange4
end module casca_node_selection
