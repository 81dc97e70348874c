!> A per-element mesh error indicator (issue 18): the jumps of the stress resultants across
!> the edges two elements of a body share, in the spirit of Zienkiewicz-Zhu. The exact
!> resultants are continuous across an edge; the elements' own are not, and an averaged
!> (recovered) field sits between the two sides, so half the jump is what each element is off
!> by there. docs/mesh_indicator.md has the definition, its scaling and the figures.
!>
!>   R = [N, (6/h) M]: N = int sigma dz, M = int sigma z dz over the thickness (per unit
!>   length), both projected on the current tangent plane; 6/h makes M a force per length
!>   (the surface stress of M, 6 M / h^2, against N / h of N).
!>   eta_e^2 = A_e / L_e * int over e's shared edges of (|[R]| / 2)^2 ds
!>   rel_e   = eta_e / (sqrt(A_e) R_rms),   R_rms^2 = int_body |R|^2 dA / A_body
!>   body figure: sqrt(sum_e eta_e^2 / int_body |R|^2 dA)
!>
!> (weighting each edge's |[R]|^2 by its length l_E gives a force^2 / length: not comparable
!> with the body's norm, a force^2. Spread over the element's area A_e as here, eta_e estimates the L2 error of
!> the resultants over e, so the eta_e^2 sum to the body's error and rel_e is the element's RMS
!> error in units of the body's RMS resultant, independent of the element's size.)
!> Lengths and areas are the initial mid-surface's; |.| is the Frobenius norm.
module casca_mesh_indicator
  use casca_kinds, only: dp
  use casca_error, only: error_t
  use casca_model, only: model_t, element_dofs
  use casca_shell_element, only: shell_stress
  use casca_shape_tri10, only: tri10_shape, tri10_normal
  use casca_quadrature, only: triangle_rule, gauss_rule
  use casca_orientation, only: vertex_elements
  implicit none
  private
  public :: indicator_t, mesh_indicator, indicator_lines, indicator_warnings, element_neighbours, &
            indicator_line_len

  !> The indicator of every element and each body's summary
  type :: indicator_t
    real(dp), allocatable :: rel(:)          !< (nelem) rel_e
    real(dp), allocatable :: body_max(:)     !< (nbody) the largest rel_e
    integer, allocatable :: body_worst(:)    !< (nbody) its element (global number; 0: none)
    real(dp), allocatable :: body_rms(:)     !< (nbody) the body figure (area-weighted RMS of rel_e)
  end type indicator_t

  integer, parameter :: indicator_line_len = 256   !< a report line: a 64-character name and figures
  integer, parameter :: ng = 3   !< Gauss points per edge: |[R]|^2 of degree 4 exactly
  integer, parameter :: nr = 18  !< components of R: N and (6/h) M, 3x3 each
  real(dp), parameter :: strain_floor = 1e-10_dp   !< below: no resultants to be relative to
  !> rel_e from which an element's resultants are taken as not resolved (off by the body's own)
  real(dp), parameter :: unresolved = 1

contains

  !> The neighbour across each edge j (vertex j to vertex j+1) of every element: nbr(j, e) the
  !> element of the same body sharing that edge (0: a boundary edge, one between bodies, or an
  !> edge of three or more elements, where no jump is defined), nedge(j, e) its edge there, and
  !> same(j, e) whether it traverses the edge the same way (casca refuses such meshes, yet the
  !> points are paired by position either way). Through the elements at each vertex node, as
  !> casca_orientation's census: the mesh's size times a vertex's valence.
  subroutine element_neighbours(conn, nnode, elem_body, nbr, nedge, same)
    integer, intent(in) :: conn(:, :), nnode, elem_body(:)
    integer, intent(out) :: nbr(3, size(conn, 2)), nedge(3, size(conn, 2))
    logical, intent(out) :: same(3, size(conn, 2))
    integer, allocatable :: start(:), at(:)
    integer :: e, f, j, k, a, b, jf, nshare
    call vertex_elements(conn, nnode, start, at)
    nbr = 0; nedge = 0; same = .false.
    do e = 1, size(conn, 2)
      do j = 1, 3
        a = conn(j, e); b = conn(mod(j, 3) + 1, e)
        nshare = 0
        do k = start(a), start(a + 1) - 1
          f = at(k)
          if (f == e .or. all(conn(1:3, f) /= b)) cycle
          nshare = nshare + 1
          if (elem_body(f) /= elem_body(e)) cycle
          do jf = 1, 3
            if (conn(jf, f) == a .and. conn(mod(jf, 3) + 1, f) == b) then
              nbr(j, e) = f; nedge(j, e) = jf; same(j, e) = .true.
            else if (conn(jf, f) == b .and. conn(mod(jf, 3) + 1, f) == a) then
              nbr(j, e) = f; nedge(j, e) = jf; same(j, e) = .false.
            end if
          end do
        end do
        if (nshare /= 1) nbr(j, e) = 0
      end do
    end do
  end subroutine element_neighbours

  !> R = [N, (6/h) M] at (xi1, xi2) of an element, by the thickness rule (zt, wt) on [-1, 1]
  !> through casca's output stress (shell_stress: the Cauchy stress at the point), projected on
  !> the current tangent plane: the transverse shear forces are left out, being one derivative
  !> less smooth: their scatter from element to element (docs/verification.md, stresses) would
  !> mask the membrane and bending jumps the indicator is about.
  !> The distance through the thickness is the initial one, h/2 xi3: both sides of an edge use
  !> the same definition, which is what the jump needs.
  pure function resultants(x0, v0, h, lam, mu, q, xi1, xi2, zt, wt, linear) result(r)
    real(dp), intent(in) :: x0(3, 10), v0(3, 10), h, lam, mu, q(7, 10), xi1, xi2, zt(:), wt(:)
    logical, intent(in) :: linear   !< a linear analysis' stress (shell_stress)
    real(dp) :: r(nr)
    real(dp) :: sig(3, 3), n(3, 3), m(3, 3), p(3, 3), nv(3), phi(10), dphi(10, 2)
    integer :: k
    n = 0; m = 0
    do k = 1, size(zt)
      sig = shell_stress(x0, v0, h, lam, mu, q, xi1, xi2, zt(k), linear)
      n = n + (0.5_dp*h*wt(k))*sig
      m = m + (0.25_dp*h*h*wt(k)*zt(k))*sig
    end do
    call tri10_shape(xi1, xi2, phi, dphi)
    nv = tri10_normal(q(1:3, :), dphi)
    nv = nv/norm2(nv)
    p = -spread(nv, 1, 3)*spread(nv, 2, 3)
    do k = 1, 3
      p(k, k) = p(k, k) + 1
    end do
    r(1:9) = reshape(matmul(p, matmul(n, p)), [9])
    r(10:18) = (6/h)*reshape(matmul(p, matmul(m, p)), [9])
  end function resultants

  !> (xi1, xi2) of the point at t in [0, 1] along edge j (vertex j to vertex j+1), and
  !> d(xi1, xi2)/dt
  pure subroutine edge_point(j, t, xi, dxi)
    integer, intent(in) :: j
    real(dp), intent(in) :: t
    real(dp), intent(out) :: xi(2), dxi(2)
    select case (j)
    case (1)
      xi = [t, 0._dp]; dxi = [1._dp, 0._dp]
    case (2)
      xi = [1 - t, t]; dxi = [-1._dp, 1._dp]
    case default
      xi = [0._dp, 1 - t]; dxi = [0._dp, -1._dp]
    end select
  end subroutine edge_point

  !> One element: R at the ng points (gt, gw on [0, 1]) of each edge, the length weights ds
  !> there (w |dX/dt|, initial mid-surface), and int_e |R|^2 dA and A_e by the area rule
  !> (axi, aw). Allocation-free: the caller holds every array.
  pure subroutine element_terms(x0, v0, h, lam, mu, q, zt, wt, gt, gw, axi, aw, linear, redge, ds, rr, area)
    real(dp), intent(in) :: x0(3, 10), v0(3, 10), h, lam, mu, q(7, 10), zt(:), wt(:), gt(ng), gw(ng)
    logical, intent(in) :: linear
    real(dp), intent(in) :: axi(:, :), aw(:)
    real(dp), intent(out) :: redge(nr, ng, 3), ds(ng, 3), rr, area
    real(dp) :: xi(2), dxi(2), phi(10), dphi(10, 2), r(nr), ja
    integer :: j, g
    do j = 1, 3
      do g = 1, ng
        call edge_point(j, gt(g), xi, dxi)
        call tri10_shape(xi(1), xi(2), phi, dphi)
        ds(g, j) = gw(g)*norm2(matmul(x0, dphi(:, 1)*dxi(1) + dphi(:, 2)*dxi(2)))
        redge(:, g, j) = resultants(x0, v0, h, lam, mu, q, xi(1), xi(2), zt, wt, linear)
      end do
    end do
    rr = 0; area = 0
    do g = 1, size(aw)
      call tri10_shape(axi(1, g), axi(2, g), phi, dphi)
      ja = aw(g)*norm2(tri10_normal(x0, dphi))
      r = resultants(x0, v0, h, lam, mu, q, axi(1, g), axi(2, g), zt, wt, linear)
      area = area + ja
      rr = rr + ja*sum(r*r)
    end do
  end subroutine element_terms

  !> eta_e^2 of element e from the edge terms of every element (module header): the squared
  !> half-jump integrated over its shared edges, spread over its area
  pure real(dp) function eta2(e, nbr, nedge, same, redge, ds, area)
    integer, intent(in) :: e, nbr(:, :), nedge(:, :)
    logical, intent(in) :: same(:, :)
    real(dp), intent(in) :: redge(:, :, :, :), ds(:, :, :), area(:)
    real(dp) :: jump2, length
    integer :: j, g, gf, f
    jump2 = 0; length = 0
    do j = 1, 3
      f = nbr(j, e)
      if (f == 0) cycle
      do g = 1, ng
        gf = g   ! traversed the other way (the rule is symmetric), point g is its ng + 1 - g
        if (.not. same(j, e)) gf = ng + 1 - g
        jump2 = jump2 + ds(g, j, e)*sum((redge(:, g, j, e) - redge(:, gf, nedge(j, e), f))**2)
        length = length + ds(g, j, e)
      end do
    end do
    eta2 = 0
    if (length > 0) eta2 = area(e)/length*0.25_dp*jump2
  end function eta2

  !> The indicator of the state q (every element, each body's largest and its figure). At
  !> output frames only: about 50 stress evaluations per element.
  subroutine mesh_indicator(model, q, ind)
    type(model_t), intent(in) :: model
    real(dp), intent(in) :: q(:)
    type(indicator_t), intent(out) :: ind
    integer, allocatable :: nbr(:, :), nedge(:, :)
    logical, allocatable :: same(:, :)
    real(dp), allocatable :: redge(:, :, :, :), ds(:, :, :), rr(:), area(:), et2(:), zt(:), wt(:), &
                             axi(:, :), aw(:), gz(:), gwz(:)
    type(error_t), allocatable :: err
    real(dp) :: gt(ng), gw(ng), rb, ab, eb
    integer :: e, b, nodes(10)

    ! 3 Gauss points through the thickness (N and M exact for stresses up to quadratic in
    ! xi3) and along the edges, 7 over the area (degree 5); the rules exist, so err stays unset
    call gauss_rule(3, zt, wt, err)
    call gauss_rule(ng, gz, gwz, err)
    gt = 0.5_dp*(gz + 1); gw = 0.5_dp*gwz
    call triangle_rule(7, axi, aw, err)
    allocate (nbr(3, model%nelem), nedge(3, model%nelem), same(3, model%nelem))
    call element_neighbours(model%conn, model%nnode, model%elem_body, nbr, nedge, same)
    allocate (redge(nr, ng, 3, model%nelem), ds(ng, 3, model%nelem), rr(model%nelem), &
              area(model%nelem), et2(model%nelem))
    do e = 1, model%nelem
      b = model%elem_body(e); nodes = model%conn(:, e)
      call element_terms(model%x0(:, nodes), model%v0(:, nodes), model%body(b)%thickness, &
                         model%body(b)%lam, model%body(b)%mu, &
                         reshape(q(element_dofs(model, e)), [7, 10]), zt, wt, gt, gw, axi, aw, &
                         model%linear, redge(:, :, :, e), ds(:, :, e), rr(e), area(e))
    end do
    do e = 1, model%nelem
      et2(e) = eta2(e, nbr, nedge, same, redge, ds, area)
    end do
    allocate (ind%rel(model%nelem), ind%body_max(model%nbody), ind%body_worst(model%nbody), &
              ind%body_rms(model%nbody))
    ind%rel = 0; ind%body_max = 0; ind%body_worst = 0; ind%body_rms = 0
    do b = 1, model%nbody
      associate (e1 => model%body(b)%elem_first, e2 => model%body(b)%elem_last)
        rb = sum(rr(e1:e2)); ab = sum(area(e1:e2)); eb = sum(et2(e1:e2))
        ! R / (E h) is a strain (of the mid-surface, or of the faces by bending): a body whose
        ! RMS strain is below 1e-10 is unloaded or moving rigidly, its resultants are round-off
        ! and a figure relative to them would be noise of order 1: its indicator stays 0
        if (e2 < e1) cycle
        if (rb <= ab*(strain_floor*model%body(b)%young*model%body(b)%thickness)**2) cycle
        ind%rel(e1:e2) = sqrt(et2(e1:e2)/area(e1:e2)/(rb/ab))
        ind%body_worst(b) = e1 - 1 + maxloc(ind%rel(e1:e2), dim=1)
        ind%body_max(b) = ind%rel(ind%body_worst(b))
        ind%body_rms(b) = sqrt(eb/rb)
      end associate
    end do
  end subroutine mesh_indicator

  !> One line per body for the end report: its largest rel_e, that element (numbered within
  !> the body, as in its mesh) and where the mean of its vertices starts, and the body figure
  function indicator_lines(model, ind) result(lines)
    type(model_t), intent(in) :: model
    type(indicator_t), intent(in) :: ind
    character(len=indicator_line_len) :: lines(model%nbody)
    real(dp) :: c(3)
    integer :: b, e
    do b = 1, model%nbody
      e = ind%body_worst(b)
      if (e == 0) then
        write (lines(b), '(a,a,a)') 'mesh indicator: ', model%body(b)%name, &
          ' max 0 (no shared edges, or no strain above 1e-10), rms 0'
        cycle
      end if
      c = sum(model%x0(:, model%conn(1:3, e)), dim=2)/3
      write (lines(b), '(a,a,a,es9.2,a,i0,a,3(1x,es10.3),a,es9.2)') 'mesh indicator: ', &
        model%body(b)%name, ' max', ind%body_max(b), ' (element ', e - model%body(b)%elem_first + 1, &
        ' at', c, '), rms', ind%body_rms(b)
    end do
  end function indicator_lines

  !> A warning for each body whose largest rel_e reaches unresolved (a thin sphere glancing off
  !> a rigid one ended at 6.27 with the figure on the report's line alone)
  function indicator_warnings(model, ind) result(lines)
    type(model_t), intent(in) :: model
    type(indicator_t), intent(in) :: ind
    character(len=indicator_line_len), allocatable :: lines(:)
    character(len=indicator_line_len) :: line
    integer :: b
    allocate (lines(0))
    do b = 1, model%nbody
      if (ind%body_worst(b) == 0 .or. ind%body_max(b) < unresolved) cycle
      write (line, '(a,a,a,i0,a,f0.2,a)') 'warning: body ''', trim(model%body(b)%name), &
        ''': at its element ', ind%body_worst(b) - model%body(b)%elem_first + 1, &
        ' the stress resultants are off by ', ind%body_max(b), ' times the body''s typical '// &
        'resultant (mesh indicator): the mesh does not resolve the stresses there; refine it '// &
        'there (docs/mesh_indicator.md)'
      lines = [lines, line]
    end do
  end function indicator_warnings
end module casca_mesh_indicator
