!> The positional shell element of Coda & Paccola (2007): a 10-node cubic triangle with 7
!> parameters per node, q(:, l) = [Y(3), G(3), A], Saint-Venant-Kirchhoff material.
!>
!>   initial  X(xi) = phi_l X^l + h/2 xi3 phi_l V^l
!>   current  y(xi) = phi_l Y^l + h/2 (xi3 + a xi3^2) phi_l G^l,    a = phi_k A^k
!>
!> The strain energy, its gradient and its Hessian are analytic. Inside the kernel the 20
!> vector parameters (Y^l, G^l) are handled together: each enters dA = d(A1 A0^-1) as
!> e_k (x) v_p with one 3-vector v_p per point, so every material and geometric term of the
!> Hessian reduces to dot products of the v_p (see formulation.md, section 1).
module casca_shell_element
  use casca_kinds, only: dp
  use casca_error, only: error_t, fatal_error
  use casca_shape_tri10, only: tri10_shape, tri10_node_xi
  use casca_quadrature, only: triangle_rule, gauss_rule
  use casca_vectors, only: cross
  implicit none
  private
  public :: shell_rule_t, shell_rule_init, shell_reference, shell_energy_force, shell_mass
  public :: ndof_node, ndof_elem, svk_lame, shell_stress, von_mises, shell_face_stretch, &
            shell_face_metric

  integer, parameter :: ndof_node = 7
  integer, parameter :: ndof_elem = 70

  !> Shape functions tabulated at the points of an area rule, and a thickness rule.
  type :: shell_rule_t
    integer :: na = 0   !< area points
    integer :: nt = 0   !< thickness points
    integer :: np = 0   !< na*nt, point ip = (ia-1)*nt + it
    real(dp), allocatable :: phi(:, :)      !< (10, na)
    real(dp), allocatable :: dphi(:, :, :)  !< (10, 2, na)
    real(dp), allocatable :: wa(:)          !< (na)
    real(dp), allocatable :: z(:), wz(:)    !< (nt)
    real(dp) :: dphi_node(10, 2, 10) = 0    !< dphi at the 10 nodes (shell_face_stretch)
  end type shell_rule_t

contains

  !> Lame constants of the 3D Saint-Venant-Kirchhoff law.
  pure subroutine svk_lame(young, poisson, lam, mu)
    real(dp), intent(in) :: young, poisson
    real(dp), intent(out) :: lam, mu
    lam = young*poisson/((1 + poisson)*(1 - 2*poisson))
    mu = young/(2*(1 + poisson))
  end subroutine svk_lame

  subroutine shell_rule_init(na, nt, rule, err)
    integer, intent(in) :: na, nt
    type(shell_rule_t), intent(out) :: rule
    type(error_t), allocatable, intent(out) :: err
    real(dp), allocatable :: xi(:, :)
    real(dp) :: phi(10)
    integer :: ia

    call triangle_rule(na, xi, rule%wa, err)
    if (allocated(err)) return
    call gauss_rule(nt, rule%z, rule%wz, err)
    if (allocated(err)) return
    rule%na = na; rule%nt = nt; rule%np = na*nt
    allocate (rule%phi(10, na), rule%dphi(10, 2, na))
    do ia = 1, na
      call tri10_shape(xi(1, ia), xi(2, ia), rule%phi(:, ia), rule%dphi(:, :, ia))
    end do
    do ia = 1, 10
      call tri10_shape(tri10_node_xi(1, ia), tri10_node_xi(2, ia), phi, rule%dphi_node(:, :, ia))
    end do
  end subroutine shell_rule_init

  !> A0 = dX/dxi at a point of the initial configuration.
  pure function initial_jacobian(phi, dphi, x0, v0, h, z) result(a0)
    real(dp), intent(in) :: phi(10), dphi(10, 2), x0(3, 10), v0(3, 10), h, z
    real(dp) :: a0(3, 3)
    real(dp) :: xz(3, 10)
    xz = x0 + (0.5_dp*h*z)*v0
    a0(:, 1) = matmul(xz, dphi(:, 1))
    a0(:, 2) = matmul(xz, dphi(:, 2))
    a0(:, 3) = (0.5_dp*h)*matmul(v0, phi)
  end function initial_jacobian

  pure function det3(a) result(d)
    real(dp), intent(in) :: a(3, 3)
    real(dp) :: d
    d = a(1, 1)*(a(2, 2)*a(3, 3) - a(3, 2)*a(2, 3)) - a(1, 2)*(a(2, 1)*a(3, 3) - a(3, 1)*a(2, 3)) &
        + a(1, 3)*(a(2, 1)*a(3, 2) - a(3, 1)*a(2, 2))
  end function det3

  !> Reference data of one element at the rule's points: binv = A0^-1 and wdet = w det(A0).
  !> detmin returns the smallest det(A0) relative to h*area scale: <= 0 means an inverted or
  !> degenerate element (or normals pointing against the element's orientation).
  pure subroutine shell_reference(rule, x0, v0, h, binv, wdet, detmin)
    type(shell_rule_t), intent(in) :: rule
    real(dp), intent(in) :: x0(3, 10), v0(3, 10), h
    real(dp), intent(out) :: binv(3, 3, rule%np), wdet(rule%np), detmin
    real(dp) :: a0(3, 3), d
    integer :: ia, it, ip

    detmin = huge(1._dp)
    do ia = 1, rule%na
      do it = 1, rule%nt
        ip = (ia - 1)*rule%nt + it
        a0 = initial_jacobian(rule%phi(:, ia), rule%dphi(:, :, ia), x0, v0, h, rule%z(it))
        d = det3(a0)
        detmin = min(detmin, d)
        if (d <= 0) then
          binv(:, :, ip) = 0; wdet(ip) = 0
          cycle
        end if
        ! inverse by cofactors
        binv(1, 1, ip) = a0(2, 2)*a0(3, 3) - a0(2, 3)*a0(3, 2)
        binv(1, 2, ip) = a0(1, 3)*a0(3, 2) - a0(1, 2)*a0(3, 3)
        binv(1, 3, ip) = a0(1, 2)*a0(2, 3) - a0(1, 3)*a0(2, 2)
        binv(2, 1, ip) = a0(2, 3)*a0(3, 1) - a0(2, 1)*a0(3, 3)
        binv(2, 2, ip) = a0(1, 1)*a0(3, 3) - a0(1, 3)*a0(3, 1)
        binv(2, 3, ip) = a0(1, 3)*a0(2, 1) - a0(1, 1)*a0(2, 3)
        binv(3, 1, ip) = a0(2, 1)*a0(3, 2) - a0(2, 2)*a0(3, 1)
        binv(3, 2, ip) = a0(1, 2)*a0(3, 1) - a0(1, 1)*a0(3, 2)
        binv(3, 3, ip) = a0(1, 1)*a0(2, 2) - a0(1, 2)*a0(2, 1)
        binv(:, :, ip) = binv(:, :, ip)/d
        wdet(ip) = rule%wa(ia)*rule%wz(it)*d
      end do
    end do
  end subroutine shell_reference

  !> Strain energy, internal force f = dU/dq and (if want_k) Hessian k = d2U/dq2 of one element.
  !> q(:, l) = [Y, G, A] of node l; f and k in the element order 7*(l-1) + c. With
  !> want_f = .false. (and no want_k) only the energy: a third of the force's cost.
  pure subroutine shell_energy_force(rule, h, lam, mu, binv, wdet, q, want_k, energy, f, k, want_f)
    type(shell_rule_t), intent(in) :: rule
    real(dp), intent(in) :: h, lam, mu
    real(dp), intent(in) :: binv(3, 3, rule%np), wdet(rule%np)
    real(dp), intent(in) :: q(7, 10)
    logical, intent(in) :: want_k
    real(dp), intent(out) :: energy, f(ndof_elem), k(ndof_elem, ndof_elem)
    logical, intent(in), optional :: want_f

    ! kvv(q, k, n, p) = d2U / d(p,k) d(q,n) for the vector parameters p, q = 1..20
    real(dp) :: kvv(20, 3, 3, 20), kva(3, 20, 10), kaa(10, 10), fv(3, 20), fa(10)
    real(dp) :: phi(10), d1(10), d2(10), y1(3), y2(3), g(3), g1(3), g2(3), a, a1, a2
    real(dp) :: z, c, s, s1, s2, s3, hz2, hz
    real(dp) :: b(3, 3), a1m(3, 3), am(3, 3), e(3, 3), sm(3, 3), pm(3, 3), bl(3, 3), w(3, 3)
    real(dp) :: v(3, 20), ut(20, 3), pv(3, 20), sv(3, 20), gram(20, 20), geo(20, 20)
    real(dp) :: da(3, 3, 10), symm(3, 3, 10), rm(3, 3, 10), tm(10), ptau(3, 10), alpha(10)
    real(dp) :: qm(3, 3), mm(3, 3), tau(3), col(3, 20), tre
    ! the force through the thickness at an area point: fv(:, l) gathers d1 fp1 + d2 fp2 (Y)
    ! and d1 fq1 + d2 fq2 + phi fq3 (G), fa phi ga0 + d1 ga1 + d2 ga2, with pbk = c P A0^-T e_k
    real(dp) :: pb1(3), pb2(3), pb3(3), fp1(3), fp2(3), fq1(3), fq2(3), fq3(3), ga0, ga1, ga2
    integer :: ia, it, ip, l, m, n, kk, nn, p
    logical :: force

    force = .true.
    if (present(want_f)) force = want_f .or. want_k
    energy = 0; fv = 0; fa = 0
    if (want_k) then
      kvv = 0; kva = 0; kaa = 0
    end if

    do ia = 1, rule%na
      phi = rule%phi(:, ia); d1 = rule%dphi(:, 1, ia); d2 = rule%dphi(:, 2, ia)
      y1 = matmul(q(1:3, :), d1); y2 = matmul(q(1:3, :), d2)
      g = matmul(q(4:6, :), phi); g1 = matmul(q(4:6, :), d1); g2 = matmul(q(4:6, :), d2)
      a = dot_product(q(7, :), phi); a1 = dot_product(q(7, :), d1); a2 = dot_product(q(7, :), d2)
      fp1 = 0; fp2 = 0; fq1 = 0; fq2 = 0; fq3 = 0; ga0 = 0; ga1 = 0; ga2 = 0

      do it = 1, rule%nt
        ip = (ia - 1)*rule%nt + it
        z = rule%z(it); c = wdet(ip); b = binv(:, :, ip)
        hz2 = 0.5_dp*h*z*z; hz = h*z
        s = 0.5_dp*h*z + a*hz2; s1 = a1*hz2; s2 = a2*hz2; s3 = 0.5_dp*h + a*hz

        ! deformation gradient A = A1 A0^-1, Green strain, SVK stress, first Piola P = A S
        a1m(:, 1) = y1 + s*g1 + s1*g
        a1m(:, 2) = y2 + s*g2 + s2*g
        a1m(:, 3) = s3*g
        am = matmul(a1m, b)
        e = 0.5_dp*matmul(transpose(am), am)
        e(1, 1) = e(1, 1) - 0.5_dp; e(2, 2) = e(2, 2) - 0.5_dp; e(3, 3) = e(3, 3) - 0.5_dp
        tre = e(1, 1) + e(2, 2) + e(3, 3)
        sm = 2*mu*e
        sm(1, 1) = sm(1, 1) + lam*tre; sm(2, 2) = sm(2, 2) + lam*tre; sm(3, 3) = sm(3, 3) + lam*tre
        energy = energy + 0.5_dp*c*sum(sm*e)
        if (.not. force) cycle
        pm = matmul(am, sm)

        ! f_p = c P : (A0^-T dA1/dq_p): each dA1/dq_p is a combination of the shape
        ! functions' values times e_k (x) b(k, :), so the point adds three vectors pbk to
        ! sums that the area point spreads over the nodes, without forming every v_p, which
        ! only the Hessian needs (the force alone in a third of the time: bench_solver)
        pb1 = c*matmul(pm, b(1, :)); pb2 = c*matmul(pm, b(2, :)); pb3 = c*matmul(pm, b(3, :))
        fp1 = fp1 + pb1; fp2 = fp2 + pb2
        fq1 = fq1 + s*pb1; fq2 = fq2 + s*pb2; fq3 = fq3 + s1*pb1 + s2*pb2 + s3*pb3
        ! thickness parameters: P : dA/dA^m = alpha_m (g1.pb1 + g2.pb2)/c + g.P tau_m (below)
        ga0 = ga0 + hz2*(dot_product(g1, pb1) + dot_product(g2, pb2)) + hz*dot_product(g, pb3)
        ga1 = ga1 + hz2*dot_product(g, pb1); ga2 = ga2 + hz2*dot_product(g, pb2)
        if (.not. want_k) cycle

        ! v_p = A0^-T dA1/dq_p for Y^l (p = l) and G^l (p = 10 + l)
        do l = 1, 10
          v(:, l) = d1(l)*b(1, :) + d2(l)*b(2, :)
          v(:, 10 + l) = (s*d1(l) + s1*phi(l))*b(1, :) + (s*d2(l) + s2*phi(l))*b(2, :) &
                         + (s3*phi(l))*b(3, :)
        end do
        pv = matmul(pm, v)

        ! thickness parameters: dA/dA^m = alpha_m W + g (x) tau_m
        do kk = 1, 3
          w(kk, :) = g1(kk)*b(1, :) + g2(kk)*b(2, :)
        end do
        do m = 1, 10
          alpha(m) = hz2*phi(m)
          tau = hz2*d1(m)*b(1, :) + hz2*d2(m)*b(2, :) + hz*phi(m)*b(3, :)
          do kk = 1, 3
            da(:, kk, m) = alpha(m)*w(:, kk) + g*tau(kk)
          end do
          ptau(:, m) = matmul(pm, tau)
        end do

        ! vector-vector blocks: lam u_p u_q^T + mu (u_q u_p^T + (v_p.v_q) A A^T) + (v_p S v_q) I
        ut = transpose(matmul(am, v))
        bl = matmul(am, transpose(am))
        sv = matmul(sm, v)
        gram = matmul(transpose(v), v)
        geo = matmul(transpose(v), sv)
        do p = 1, 20
          do nn = 1, 3
            do kk = 1, 3
              kvv(:, kk, nn, p) = kvv(:, kk, nn, p) + c*(lam*ut(p, kk)*ut(:, nn) &
                                  + mu*(ut(p, nn)*ut(:, kk) + bl(kk, nn)*gram(:, p)))
            end do
            kvv(:, nn, nn, p) = kvv(:, nn, nn, p) + c*geo(:, p)
          end do
        end do

        ! thickness-parameter blocks
        do m = 1, 10
          tm(m) = sum(am*da(:, :, m))
          mm = matmul(transpose(da(:, :, m)), am)
          symm(:, :, m) = 0.5_dp*(mm + transpose(mm))
          rm(:, :, m) = matmul(da(:, :, m), sm)
          qm = lam*tm(m)*am + 2*mu*matmul(am, symm(:, :, m)) + rm(:, :, m)
          col = matmul(qm, v)
          do l = 1, 10   ! d2A1/dG dA: the only non-zero second derivative of the map
            col(:, 10 + l) = col(:, 10 + l) + alpha(m)*pv(:, l) + phi(l)*ptau(:, m)
          end do
          kva(:, :, m) = kva(:, :, m) + c*col
        end do
        do n = 1, 10
          do m = n, 10
            kaa(m, n) = kaa(m, n) + c*(lam*tm(m)*tm(n) + 2*mu*sum(symm(:, :, m)*symm(:, :, n)) &
                                       + sum(rm(:, :, m)*da(:, :, n)))
          end do
        end do
      end do
      if (.not. force) cycle
      do l = 1, 10
        fv(:, l) = fv(:, l) + d1(l)*fp1 + d2(l)*fp2
        fv(:, 10 + l) = fv(:, 10 + l) + d1(l)*fq1 + d2(l)*fq2 + phi(l)*fq3
        fa(l) = fa(l) + phi(l)*ga0 + d1(l)*ga1 + d2(l)*ga2
      end do
    end do

    ! scatter to the element order
    do l = 1, 10
      f(7*l - 6:7*l - 4) = fv(:, l)
      f(7*l - 3:7*l - 1) = fv(:, 10 + l)
      f(7*l) = fa(l)
    end do
    if (.not. want_k) return
    do p = 1, 20
      do kk = 1, 3
        do l = 1, 10
          do nn = 1, 3
            k(vidx(nn, l), vidx(kk, p)) = kvv(l, kk, nn, p)
            k(vidx(nn, l + 10), vidx(kk, p)) = kvv(l + 10, kk, nn, p)
          end do
          k(7*l, vidx(kk, p)) = kva(kk, p, l)
          k(vidx(kk, p), 7*l) = kva(kk, p, l)
        end do
      end do
    end do
    do n = 1, 10
      do m = n, 10
        k(7*m, 7*n) = kaa(m, n)
        k(7*n, 7*m) = kaa(m, n)
      end do
    end do
  contains
    !> element index of component kk of vector parameter p
    pure integer function vidx(kc, pp)
      integer, intent(in) :: kc, pp
      if (pp <= 10) then
        vidx = 7*(pp - 1) + kc
      else
        vidx = 7*(pp - 11) + 3 + kc
      end if
    end function vidx
  end subroutine shell_energy_force

  !> Cauchy stress (global axes) at (xi1, xi2, xi3) of the element, for output:
  !> sigma = F S F^T / det F with F = A1 A0^-1 and S the SVK stress of the Green strain.
  !> xi3 = -1 is the bottom face, 0 the mid-surface, +1 the top face: the side the initial
  !> fibre V points to. With linear (a linear analysis), the stress of the strain linear in
  !> q - q0, sym(dA1 A0^-1): the Green strain's square of each rotation would swamp it.
  pure function shell_stress(x0, v0, h, lam, mu, q, xi1, xi2, xi3, linear) result(sig)
    real(dp), intent(in) :: x0(3, 10), v0(3, 10), h, lam, mu, q(7, 10), xi1, xi2, xi3
    logical, intent(in), optional :: linear
    real(dp) :: sig(3, 3)
    real(dp) :: phi(10), dphi(10, 2), a0(3, 3), f(3, 3), e(3, 3), s(3, 3), inv(3, 3), d, q2(7, 10)
    integer :: i
    logical :: lin
    lin = .false.
    if (present(linear)) lin = linear
    call tri10_shape(xi1, xi2, phi, dphi)
    a0 = initial_jacobian(phi, dphi, x0, v0, h, xi3)
    d = det3(a0)
    inv(:, 1) = cross(a0(:, 2), a0(:, 3))/d   ! rows of A0^-1, stored as columns
    inv(:, 2) = cross(a0(:, 3), a0(:, 1))/d
    inv(:, 3) = cross(a0(:, 1), a0(:, 2))/d
    if (lin) then
      ! A1 is quadratic in q (the fibre times the thickness parameter), so the central
      ! difference about q0 = (X, V, 0) is exactly its part linear in q - q0
      q2(1:3, :) = 2*x0 - q(1:3, :); q2(4:6, :) = 2*v0 - q(4:6, :); q2(7, :) = -q(7, :)
      f = 0.5_dp*matmul(current_jacobian(phi, dphi, q, h, xi3) - current_jacobian(phi, dphi, q2, h, xi3), &
                        transpose(inv))
      e = 0.5_dp*(f + transpose(f))
    else
      f = matmul(current_jacobian(phi, dphi, q, h, xi3), transpose(inv))
      e = 0.5_dp*matmul(transpose(f), f)
      do i = 1, 3
        e(i, i) = e(i, i) - 0.5_dp
      end do
    end if
    s = 2*mu*e
    do i = 1, 3
      s(i, i) = s(i, i) + lam*(e(1, 1) + e(2, 2) + e(3, 3))
    end do
    if (lin) then
      sig = s
    else
      sig = matmul(f, matmul(s, transpose(f)))/det3(f)
    end if
  end function shell_stress

  !> The faces' metrics at the element's nodes before it moves: m0(:, k, l) = the dot products
  !> [a1.a1, a1.a2, a2.a2] of the in-plane columns of A0 on face k (xi3 = -1, +1) at node l
  pure subroutine shell_face_metric(rule, x0, v0, h, m0)
    type(shell_rule_t), intent(in) :: rule
    real(dp), intent(in) :: x0(3, 10), v0(3, 10), h
    real(dp), intent(out) :: m0(3, 2, 10)
    real(dp) :: a(3, 2)
    integer :: l, k
    do l = 1, 10
      do k = 1, 2
        a = matmul(x0 + (h*(k - 1.5_dp))*v0, rule%dphi_node(:, :, l))
        m0(:, k, l) = [dot_product(a(:, 1), a(:, 1)), dot_product(a(:, 1), a(:, 2)), &
                       dot_product(a(:, 2), a(:, 2))]
      end do
    end do
  end subroutine shell_face_metric

  !> The least stretch along the faces at the element's nodes, and the node (1..10): the smaller
  !> root of det(M1 - s^2 M0) = 0, M0 and M1 the face's metric before (shell_face_metric) and
  !> now. A fold bent to a radius near the thickness squeezes its inner face along itself as a
  !> squeeze through the thickness does the fibre. At a node the shape functions are 1 there
  !> and 0 at the others, so G and A are the node's own: dy/dxi_j = Y,j + s G,j + s_j G with
  !> s = h/2 (z + A), s_j = h/2 A,j on the face z = +-1 (current_jacobian).
  pure subroutine shell_face_stretch(rule, m0, h, q, stretch, node)
    type(shell_rule_t), intent(in) :: rule
    real(dp), intent(in) :: m0(3, 2, 10), h, q(7, 10)
    real(dp), intent(out) :: stretch
    integer, intent(out) :: node
    real(dp) :: d(7, 20), a(3, 2), m1(3), b, c, s2
    integer :: l, k
    stretch = huge(1._dp); node = 1
    d = matmul(q, reshape(rule%dphi_node, [10, 20]))   ! Y,j G,j A,j at node l: d(:, 2l-1 : 2l)
    do l = 1, 10
      do k = 1, 2
        a = d(1:3, 2*l - 1:2*l) + (0.5_dp*h*(2*k - 3 + q(7, l)))*d(4:6, 2*l - 1:2*l)
        a(:, 1) = a(:, 1) + (0.5_dp*h*d(7, 2*l - 1))*q(4:6, l)
        a(:, 2) = a(:, 2) + (0.5_dp*h*d(7, 2*l))*q(4:6, l)
        m1 = [dot_product(a(:, 1), a(:, 1)), dot_product(a(:, 1), a(:, 2)), dot_product(a(:, 2), a(:, 2))]
        associate (n => m0(:, k, l))
          b = n(1)*m1(3) + n(3)*m1(1) - 2*n(2)*m1(2)
          c = n(1)*n(3) - n(2)**2
          s2 = huge(1._dp)   ! (a face through its centre of curvature has no metric: refused)
          if (c > 0) s2 = (b - sqrt(max(b*b - 4*c*(m1(1)*m1(3) - m1(2)**2), 0._dp)))/(2*c)
        end associate
        if (s2 < stretch) then
          stretch = s2; node = l
        end if
      end do
    end do
    stretch = sqrt(max(stretch, 0._dp))
  end subroutine shell_face_stretch

  !> A1 = dy/dxi at a point of the current configuration (the map of the module header):
  !> dy/dxi_j = Y,j + s G,j + s_j G and dy/dxi3 = (h/2 + a h z) G, s = h/2 (z + a z^2),
  !> s_j = h/2 z^2 a,j; the same terms the energy kernel forms inline per thickness point.
  pure function current_jacobian(phi, dphi, q, h, z) result(a1)
    real(dp), intent(in) :: phi(10), dphi(10, 2), q(7, 10), h, z
    real(dp) :: a1(3, 3)
    real(dp) :: g(3), a, hz2, s
    integer :: j
    g = matmul(q(4:6, :), phi)
    a = dot_product(q(7, :), phi)
    hz2 = 0.5_dp*h*z*z
    s = 0.5_dp*h*z + a*hz2
    do j = 1, 2
      a1(:, j) = matmul(q(1:3, :), dphi(:, j)) + s*matmul(q(4:6, :), dphi(:, j)) &
                 + (hz2*dot_product(q(7, :), dphi(:, j)))*g
    end do
    a1(:, 3) = (0.5_dp*h + a*h*z)*g
  end function current_jacobian

  !> Von Mises equivalent stress of a stress tensor.
  pure real(dp) function von_mises(sig) result(vm)
    real(dp), intent(in) :: sig(3, 3)
    vm = sqrt(0.5_dp*((sig(1, 1) - sig(2, 2))**2 + (sig(2, 2) - sig(3, 3))**2 &
                      + (sig(3, 3) - sig(1, 1))**2) &
              + 3*(sig(1, 2)**2 + sig(2, 3)**2 + sig(1, 3)**2))
  end function von_mises


  !> Constant consistent mass of one element from the part of the map linear in (Y, G):
  !> y_K = phi_l Y^l + h/2 xi3 phi_l G^l. m(p, q) is the scalar mass between vector
  !> parameters p, q (1..10 = Y^l, 11..20 = G^l); the 3x3 block is m(p, q) times I.
  pure subroutine shell_mass(rule, x0, v0, h, rho, m)
    type(shell_rule_t), intent(in) :: rule
    real(dp), intent(in) :: x0(3, 10), v0(3, 10), h, rho
    real(dp), intent(out) :: m(20, 20)
    real(dp) :: chi(20), c
    integer :: ia, it, p

    m = 0
    do ia = 1, rule%na
      do it = 1, rule%nt
        c = rho*rule%wa(ia)*rule%wz(it) &
            *det3(initial_jacobian(rule%phi(:, ia), rule%dphi(:, :, ia), x0, v0, h, rule%z(it)))
        chi(1:10) = rule%phi(:, ia)
        chi(11:20) = (0.5_dp*h*rule%z(it))*rule%phi(:, ia)
        do p = 1, 20
          m(:, p) = m(:, p) + (c*chi(p))*chi
        end do
      end do
    end do
  end subroutine shell_mass
end module casca_shell_element
