!> A scene as the solver sees it: all bodies' nodes and elements in one numbering, materials,
!> element reference data (A0^-1, w det A0, mass), prescribed parameters, dead loads, follower
!> pressures and moments.
!> Parameters of node i are dofs 7(i-1)+1..7(i-1)+7 = [Y(3), G(3), A].
module casca_model
  use casca_kinds, only: dp
  use casca_error, only: error_t, fatal_error
  use casca_strings, only: rtoa
  use casca_mesh, only: mesh_t, nen
  use casca_shape_tri10, only: tri10_shape, tri10_normal, tri10_node_xi
  use casca_shell_element, only: shell_rule_t, shell_rule_init, shell_reference, shell_mass, &
                                 svk_lame, ndof_node, ndof_elem, shell_face_stretch, &
                                 shell_face_metric, shell_energy_force
  implicit none
  private
  public :: body_t, model_t, model_add_body, model_finalize, dof, element_dofs, reference_state
  public :: area_points, thick_points, element_area, thinnest, thickness_stretch, least_face_stretch, &
            follower_loaded
  public :: element_energy

  integer, parameter :: area_points = 7    !< 7x3 points: the fewest with exactly 6 zero modes
  integer, parameter :: thick_points = 3

  type :: body_t
    character(len=:), allocatable :: name
    real(dp) :: young = 0, poisson = 0, density = 0, thickness = 0, lam = 0, mu = 0
    integer :: node_first = 0, node_last = -1, elem_first = 0, elem_last = -1
    real(dp) :: gravity(3) = 0   !< the run's and the body's own [m/s^2]
    !> [kg]: the consistent mass's Y-Y entries of one component summed (model_finalize)
    real(dp) :: mass = 0
  end type body_t

  type :: model_t
    integer :: nnode = 0, nelem = 0, ndof = 0, nbody = 0
    type(body_t), allocatable :: body(:)
    real(dp), allocatable :: x0(:, :)        !< (3, nnode) initial mid-surface
    real(dp), allocatable :: v0(:, :)        !< (3, nnode) initial unit fibre (normal)
    logical, allocatable :: exact_normal(:)  !< (nnode) normal given by the generator
    integer, allocatable :: conn(:, :)       !< (nen, nelem)
    integer, allocatable :: elem_body(:), node_body(:)
    type(shell_rule_t) :: rule               !< stiffness rule
    real(dp), allocatable :: binv(:, :, :, :), wdet(:, :)   !< (3,3,np,nelem), (np,nelem)
    real(dp), allocatable :: face_metric(:, :, :, :)        !< (3,2,10,nelem) shell_face_metric
    real(dp), allocatable :: emass(:, :, :)  !< (20, 20, nelem) scalar element mass
    logical, allocatable :: fixed(:)         !< (ndof) prescribed parameters
    real(dp), allocatable :: fext(:)         !< (ndof) dead nodal loads
    real(dp), allocatable :: pressure(:)     !< (nelem) follower pressure on each element [Pa]
    !> (nelem) the element's body's loaded elements make closed surfaces under one pressure:
    !> its work is p (V - V0) there (casca_follower_loads), a sum along the path elsewhere
    logical, allocatable :: pressure_closed(:)
    !> (3, nnode) a moment about a fixed axis on each node's fibre [N m] (casca_moment_load)
    real(dp), allocatable :: moment(:, :)
    !> (nnode) the element whose tangent entries carry the node's moment stiffness: the first
    !> holding the node, so that one rank adds it
    integer, allocatable :: moment_elem(:)
    logical :: load_stiffness = .true.       !< the pressures' and moments' load stiffness in the tangent
    logical :: linear = .false.              !< a linear analysis: energies and stresses of the
                                             !< strain linear in q - q0
    real(dp) :: length = 1                   !< size of the scene (bounding-box diagonal)
  end type model_t

contains

  elemental integer function dof(node, comp)
    integer, intent(in) :: node, comp
    dof = ndof_node*(node - 1) + comp
  end function dof

  !> The node squeezed most through its thickness and its stretch there, |G| (1 - 2|A|) at
  !> its nearer face (G starts as a unit vector; A tilts the stretch through the thickness)
  pure subroutine thinnest(model, q, node, stretch)
    type(model_t), intent(in) :: model
    real(dp), intent(in) :: q(:)
    integer, intent(out) :: node
    real(dp), intent(out) :: stretch
    real(dp) :: s
    integer :: n
    node = 0; stretch = huge(1._dp)
    do n = 1, model%nnode
      s = thickness_stretch(q, n)*(1 - 2*abs(q(dof(n, 7))))
      if (s < stretch) then
        stretch = s; node = n
      end if
    end do
  end subroutine thinnest

  !> Node n's thickness now over its initial one, |G|: its faces xi3 = +-1 are at
  !> Y + (h/2)(+-1 + A) G (casca_shell_element), h |G| apart along the fibre, and G starts as
  !> a unit vector. A shifts both faces alike: it tilts the stretch through the thickness
  !> about this mean (thinnest's nearer face), and leaves the thickness as it is.
  pure real(dp) function thickness_stretch(q, n)
    real(dp), intent(in) :: q(:)
    integer, intent(in) :: n
    thickness_stretch = norm2(q(dof(n, 4):dof(n, 6)))
  end function thickness_stretch

  !> The node whose face is stretched least along itself (shell_face_stretch) and that stretch
  pure subroutine least_face_stretch(model, q, node, stretch)
    type(model_t), intent(in) :: model
    real(dp), intent(in) :: q(:)
    integer, intent(out) :: node
    real(dp), intent(out) :: stretch
    real(dp) :: s
    integer :: e, n
    node = 0; stretch = huge(1._dp)
    do e = 1, model%nelem
      call shell_face_stretch(model%rule, model%face_metric(:, :, :, e), model%body(model%elem_body(e))%thickness, &
                              reshape(q(element_dofs(model, e)), [ndof_node, nen]), s, n)
      if (s < stretch) then
        stretch = s; node = model%conn(n, e)
      end if
    end do
  end subroutine least_face_stretch

  !> The 70 dofs of element e in the element order 7(l-1)+c.
  pure function element_dofs(model, e) result(d)
    type(model_t), intent(in) :: model
    integer, intent(in) :: e
    integer :: d(7*nen)
    integer :: l, c
    do l = 1, nen
      do c = 1, ndof_node
        d(ndof_node*(l - 1) + c) = dof(model%conn(l, e), c)
      end do
    end do
  end function element_dofs

  !> Append a body (mesh and material) to the model.
  subroutine model_add_body(model, name, mesh, young, poisson, density, thickness)
    type(model_t), intent(inout) :: model
    character(len=*), intent(in) :: name
    type(mesh_t), intent(in) :: mesh
    real(dp), intent(in) :: young, poisson, density, thickness
    type(body_t), allocatable :: bodies(:)
    real(dp), allocatable :: x(:, :), v(:, :)
    logical, allocatable :: ex(:)
    integer, allocatable :: conn(:, :), eb(:), nb(:)
    type(body_t) :: b
    integer :: nn, ne

    nn = model%nnode; ne = model%nelem
    b%name = name
    b%young = young; b%poisson = poisson; b%density = density; b%thickness = thickness
    call svk_lame(young, poisson, b%lam, b%mu)
    b%node_first = nn + 1; b%node_last = nn + mesh%nnode
    b%elem_first = ne + 1; b%elem_last = ne + mesh%nelem
    if (model%nbody == 0) then
      allocate (model%body(0), model%x0(3, 0), model%v0(3, 0), model%exact_normal(0), &
                model%conn(nen, 0), model%elem_body(0), model%node_body(0))
    end if
    bodies = [model%body, b]
    call move_alloc(bodies, model%body)
    allocate (x(3, nn + mesh%nnode), v(3, nn + mesh%nnode), ex(nn + mesh%nnode))
    x(:, 1:nn) = model%x0; x(:, nn + 1:) = mesh%x
    v = 0; v(:, 1:nn) = model%v0
    ex(1:nn) = model%exact_normal
    ex(nn + 1:) = size(mesh%normal, 2) == mesh%nnode
    if (ex(nn + 1)) v(:, nn + 1:) = mesh%normal
    call move_alloc(x, model%x0); call move_alloc(v, model%v0); call move_alloc(ex, model%exact_normal)
    allocate (conn(nen, ne + mesh%nelem))
    conn(:, 1:ne) = model%conn; conn(:, ne + 1:) = mesh%conn + nn
    call move_alloc(conn, model%conn)
    eb = [model%elem_body, spread(model%nbody + 1, 1, mesh%nelem)]
    nb = [model%node_body, spread(model%nbody + 1, 1, mesh%nnode)]
    call move_alloc(eb, model%elem_body); call move_alloc(nb, model%node_body)
    model%nbody = model%nbody + 1
    model%nnode = nn + mesh%nnode; model%nelem = ne + mesh%nelem
  end subroutine model_add_body

  !> Normals, element reference data and masses; arrays for restraints and loads.
  subroutine model_finalize(model, err, body)
    type(model_t), intent(inout) :: model
    type(error_t), allocatable, intent(out) :: err
    integer, intent(out), optional :: body   !< the body err is about (0: none), which the caller names
    type(shell_rule_t) :: mrule
    real(dp) :: phi(10), dphi(10, 2), detmin, h
    integer :: e, l, i
    character(len=200) :: msg

    if (present(body)) body = 0
    model%ndof = ndof_node*model%nnode
    call shell_rule_init(area_points, thick_points, model%rule, err)
    if (allocated(err)) return
    call shell_rule_init(12, 3, mrule, err)   ! degree 6 in-plane: exact mass of flat elements
    if (allocated(err)) return

    ! averaged normals where the generator gave none [formulation.md choice]
    do e = 1, model%nelem
      do l = 1, nen
        i = model%conn(l, e)
        if (model%exact_normal(i)) cycle
        call tri10_shape(tri10_node_xi(1, l), tri10_node_xi(2, l), phi, dphi)
        model%v0(:, i) = model%v0(:, i) + tri10_normal(model%x0(:, model%conn(:, e)), dphi)
      end do
    end do
    do i = 1, model%nnode
      if (norm2(model%v0(:, i)) <= 0) then
        write (msg, '(a,i0,a)') 'node ', i - model%body(model%node_body(i))%node_first + 1, &
          ' has no normal: the elements around it are degenerate (zero area)'
        if (present(body)) body = model%node_body(i)
        call fatal_error(err, trim(msg)); return
      end if
      model%v0(:, i) = model%v0(:, i)/norm2(model%v0(:, i))
    end do

    allocate (model%binv(3, 3, model%rule%np, model%nelem), model%wdet(model%rule%np, model%nelem))
    allocate (model%emass(20, 20, model%nelem), model%face_metric(3, 2, nen, model%nelem))
    do e = 1, model%nelem
      h = model%body(model%elem_body(e))%thickness
      call shell_face_metric(model%rule, model%x0(:, model%conn(:, e)), model%v0(:, model%conn(:, e)), &
                             h, model%face_metric(:, :, :, e))
      call shell_reference(model%rule, model%x0(:, model%conn(:, e)), model%v0(:, model%conn(:, e)), &
                           h, model%binv(:, :, :, e), model%wdet(:, e), detmin)
      if (detmin <= 0) then
        write (msg, '(a,i0)') 'element ', e - model%body(model%elem_body(e))%elem_first + 1
        if (present(body)) body = model%elem_body(e)
        ! (a mid-surface that is sound: the faces cross through the centre of curvature)
        call shell_reference(model%rule, model%x0(:, model%conn(:, e)), model%v0(:, model%conn(:, e)), &
                             1e-6_dp*h, model%binv(:, :, :, e), model%wdet(:, e), detmin)
        if (detmin > 0) then
          call fatal_error(err, trim(msg)//' turns inside out through its thickness, '//rtoa(h)// &
            ' m: its faces pass its centre of curvature there (a length in another unit?)')
        else
          call fatal_error(err, trim(msg)//' is degenerate or inverted (det A0 <= 0 at a quadrature point)')
        end if
        return
      end if
      call shell_mass(mrule, model%x0(:, model%conn(:, e)), model%v0(:, model%conn(:, e)), h, &
                      model%body(model%elem_body(e))%density, model%emass(:, :, e))
      associate (bd => model%body(model%elem_body(e)))
        bd%mass = bd%mass + sum(model%emass(1:10, 1:10, e))
      end associate
    end do
    allocate (model%fixed(model%ndof), model%fext(model%ndof))
    model%fixed = .false.; model%fext = 0
    allocate (model%pressure(model%nelem), model%pressure_closed(model%nelem))
    model%pressure = 0; model%pressure_closed = .false.
    allocate (model%moment(3, model%nnode), model%moment_elem(model%nnode))
    model%moment = 0
    do e = model%nelem, 1, -1
      model%moment_elem(model%conn(:, e)) = e
    end do
    model%length = norm2(maxval(model%x0, dim=2) - minval(model%x0, dim=2))
  end subroutine model_finalize

  !> Element e's strain energy at q; in a linear analysis (model%linear) 1/2 dq . K0 dq with
  !> dq = q - q0 and K0 the element's stiffness unstressed, the energy of the linear strains
  !> (the Green strain's would count the square of each rotation)
  function element_energy(model, q, e) result(w)
    type(model_t), intent(in) :: model
    real(dp), intent(in) :: q(:)
    integer, intent(in) :: e
    real(dp) :: w
    real(dp) :: qe(ndof_node, nen), q0(ndof_node, nen), fe(ndof_elem), ke(ndof_elem, ndof_elem), d(ndof_elem)
    qe = reshape(q(element_dofs(model, e)), [ndof_node, nen])
    associate (b => model%body(model%elem_body(e)))
      if (.not. model%linear) then
        call shell_energy_force(model%rule, b%thickness, b%lam, b%mu, model%binv(:, :, :, e), &
                                model%wdet(:, e), qe, .false., w, fe, ke, want_f=.false.)
        return
      end if
      q0(1:3, :) = model%x0(:, model%conn(:, e)); q0(4:6, :) = model%v0(:, model%conn(:, e)); q0(7, :) = 0
      call shell_energy_force(model%rule, b%thickness, b%lam, b%mu, model%binv(:, :, :, e), &
                              model%wdet(:, e), q0, .true., w, fe, ke)
    end associate
    d = reshape(qe - q0, [ndof_elem])
    w = 0.5_dp*dot_product(d, matmul(ke, d))
  end function element_energy

  !> Body b carries a load that depends on its state: a follower pressure or a moment
  pure logical function follower_loaded(model, b)
    type(model_t), intent(in) :: model
    integer, intent(in) :: b
    associate (bd => model%body(b))
      follower_loaded = any(model%pressure(bd%elem_first:bd%elem_last) /= 0) .or. &
                        any(model%moment(:, bd%node_first:bd%node_last) /= 0)
    end associate
  end function follower_loaded

  !> q of the unstressed initial state: Y = X, G = V, A = 0.
  pure subroutine reference_state(model, q)
    type(model_t), intent(in) :: model
    real(dp), intent(out) :: q(:)
    integer :: i
    do i = 1, model%nnode
      q(dof(i, 1):dof(i, 3)) = model%x0(:, i)
      q(dof(i, 4):dof(i, 6)) = model%v0(:, i)
      q(dof(i, 7)) = 0
    end do
  end subroutine reference_state

  !> Area of element e's cubic mid-surface (the model's area rule)
  pure real(dp) function element_area(model, e) result(a)
    type(model_t), intent(in) :: model
    integer, intent(in) :: e
    integer :: ia
    a = 0
    do ia = 1, area_points
      a = a + model%rule%wa(ia)* &
          norm2(tri10_normal(model%x0(:, model%conn(:, e)), model%rule%dphi(:, :, ia)))
    end do
  end function element_area

end module casca_model
