!> The rows of face constraints against finite differences of their gaps: a blade (h 10 mm,
!> 4 x 4 cells) pressed edge-first at 62 degrees (its rim in the offset's fade band) into a
!> bumpy plate, positions and fibres perturbed at random. For every active constraint, with
!> its point, side and faces held, the gap's row (contact_rows' C) and the force's row at
!> the midpoint (af = 1/2, contact_force_points) are each the gradient of the gap g(q) there
!> on every parameter of the model (central differences, step 1e-7 m): relative error, the
!> largest entry difference over the largest entry, below 1e-6 (the differences' own error
!> is about 1e-9). Without the gap's derivative through the target normal's turn the error
!> is of the row's own size (0.77 with nodal normals, 1.01 with element normals: the old
!> row, checked here with its lever left out, nl = 0). The force row has no net force and
!> no moment about the origin at the midpoint (positions and fibres), to 1e-10 of the
!> row's size. Nodal normals (the default) and element normals. The blade's rim nodes lie in
!> the offset's fade band: there the gap's second derivative along n on the node's fibre,
!> -wgg (Newton's bend row, contact_rows), equals central second differences within 1e-4 of
!> its largest value (at least 4 such nodes).
!> Second scene: a plate (h 10 mm, 4 x 4 cells, tilted 30 degrees) pressed 2 mm into the
!> top edge of a band standing on its rim (one pass: the plate's nodes are the impactor),
!> so that its nodes meet the band's rounded edge (around_rim): the same checks, the row
!> without its lever off by more than 0.1.
program test_contact_lever
  use casca_kinds, only: dp
  use casca_error, only: error_t
  use casca_mesh, only: mesh_t
  use casca_mesh_generators, only: mesh_plate
  use casca_model, only: model_t, model_add_body, model_finalize, reference_state, dof
  use casca_contact, only: contact_t, constraint_t, contact_init, around_rim
  use casca_contact_active_set, only: contact_update
  use casca_contact_projection, only: positions, constraint_geometry, constraint_row, max_row
  use casca_contact_rows, only: contact_force_points
  use casca_obstacle, only: obstacle_t
  use casca_vectors, only: cross
  use casca_check, only: check_le, check_true, check_summary
  implicit none

  type(model_t) :: model
  real(dp), allocatable :: q(:), qn(:)

  call scene(model, q, qn)
  call check_rows(.true., 'nodal normals')
  call check_rows(.false., 'element normals')
  call rim_scene(model, q, qn)
  call check_rows(.true., 'rim')
  call check_summary()

contains

  !> blade over a bumpy plate; q: pressed in, perturbed; qn: another state near it
  subroutine scene(model, q, qn)
    type(model_t), intent(out) :: model
    real(dp), allocatable, intent(out) :: q(:), qn(:)
    type(mesh_t) :: blade, plate
    type(error_t), allocatable :: err
    real(dp) :: a, r(3, 3), z0
    integer :: i, nseed
    integer, allocatable :: seed(:)
    call random_seed(size=nseed)
    seed = [(7919*i + 13, i=1, nseed)]
    call random_seed(put=seed)
    call mesh_plate(0.1_dp, 0.1_dp, 4, 4, blade, err)
    if (allocated(err)) error stop 'mesh'
    a = 62*acos(-1._dp)/180
    r = reshape([1._dp, 0._dp, 0._dp, 0._dp, cos(a), sin(a), 0._dp, -sin(a), cos(a)], [3, 3])
    blade%x = matmul(r, blade%x); blade%normal = matmul(r, blade%normal)
    ! the lower edge 2 mm into the faces (offset 5 mm + 5 mm cos 62 less its fade)
    z0 = minval(blade%x(3, :))
    blade%x(1, :) = blade%x(1, :) - 0.05_dp; blade%x(3, :) = blade%x(3, :) - z0 + 0.0055_dp
    call mesh_plate(0.3_dp, 0.3_dp, 6, 6, plate, err)
    if (allocated(err)) error stop 'mesh'
    plate%x(1:2, :) = plate%x(1:2, :) - 0.15_dp
    plate%x(3, :) = 0.004_dp*sin(20*plate%x(1, :) + 0.3_dp)*cos(15*plate%x(2, :) + 0.2_dp)
    call model_add_body(model, 'blade', blade, 210e9_dp, 0.3_dp, 7800._dp, 0.01_dp)
    call model_add_body(model, 'plate', plate, 210e9_dp, 0.3_dp, 7800._dp, 0.01_dp)
    call perturbed(model, q, qn)
  end subroutine scene

  !> a plate tilted 30 degrees about x, 2 mm into the rounded top edge (y = 0, z = 0) of a
  !> band standing in the x-z plane
  subroutine rim_scene(model, q, qn)
    type(model_t), intent(out) :: model
    real(dp), allocatable, intent(out) :: q(:), qn(:)
    type(mesh_t) :: plate, band
    type(error_t), allocatable :: err
    real(dp) :: a, r(3, 3)
    call mesh_plate(0.1_dp, 0.1_dp, 4, 4, plate, err)
    if (allocated(err)) error stop 'mesh'
    a = 30*acos(-1._dp)/180
    r = reshape([1._dp, 0._dp, 0._dp, 0._dp, cos(a), sin(a), 0._dp, -sin(a), cos(a)], [3, 3])
    plate%x(1:2, :) = plate%x(1:2, :) - 0.05_dp
    plate%x = matmul(r, plate%x); plate%normal = matmul(r, plate%normal)
    plate%x(1, :) = plate%x(1, :) + 0.013_dp; plate%x(2, :) = plate%x(2, :) + 0.002_dp
    plate%x(3, :) = plate%x(3, :) + 0.003_dp
    call mesh_plate(0.3_dp, 0.1_dp, 6, 2, band, err)
    if (allocated(err)) error stop 'mesh'
    a = acos(-1._dp)/2
    r = reshape([1._dp, 0._dp, 0._dp, 0._dp, cos(a), sin(a), 0._dp, -sin(a), cos(a)], [3, 3])
    band%x(1, :) = band%x(1, :) - 0.15_dp; band%x(2, :) = band%x(2, :) - 0.1_dp
    band%x = matmul(r, band%x); band%normal = matmul(r, band%normal)
    call model_add_body(model, 'plate', plate, 210e9_dp, 0.3_dp, 7800._dp, 0.01_dp)
    call model_add_body(model, 'band', band, 210e9_dp, 0.3_dp, 7800._dp, 0.01_dp)
    call perturbed(model, q, qn)
  end subroutine rim_scene

  !> the reference state perturbed at random (q), and another state near it (qn)
  subroutine perturbed(model, q, qn)
    type(model_t), intent(inout) :: model
    real(dp), allocatable, intent(out) :: q(:), qn(:)
    type(error_t), allocatable :: err
    real(dp) :: p(6)
    integer :: n
    call model_finalize(model, err)
    if (allocated(err)) error stop 'model'
    allocate (q(model%ndof))
    call reference_state(model, q)
    do n = 1, model%nnode
      call random_number(p)
      q(dof(n, 1):dof(n, 3)) = q(dof(n, 1):dof(n, 3)) + 2e-4_dp*(p(1:3) - 0.5_dp)
      q(dof(n, 4):dof(n, 6)) = q(dof(n, 4):dof(n, 6)) + 0.1_dp*(p(4:6) - 0.5_dp)
    end do
    qn = q
    do n = 1, model%nnode
      call random_number(p)
      qn(dof(n, 1):dof(n, 3)) = qn(dof(n, 1):dof(n, 3)) + 2e-4_dp*(p(1:3) - 0.5_dp)
      qn(dof(n, 4):dof(n, 6)) = qn(dof(n, 4):dof(n, 6)) + 0.02_dp*(p(4:6) - 0.5_dp)
    end do
  end subroutine perturbed

  subroutine check_rows(nodal, label)
    logical, intent(in) :: nodal
    character(len=*), intent(in) :: label
    type(contact_t) :: c
    type(constraint_t) :: old
    real(dp), allocatable :: qf(:)
    real(dp) :: e_gap, e_force, e_old, mom, maxlever
    integer :: added, k
    call contact_init(model, reshape([1, 2], [2, 1]), [obstacle_t ::], 1e-9_dp, .true., c)
    c%opt%nodal_normal = nodal
    call contact_update(c, model, q, .true., added)
    call check_true(label//': constraints made ('//itoa(c%set%nact)//')', c%set%nact >= 4)
    if (label == 'rim') call check_true(label//': constraints around the rim ('// &
                                        itoa(count(c%set%act(1:c%set%nact)%side == around_rim))//')', &
                                        count(c%set%act(1:c%set%nact)%side == around_rim) >= 4)
    ! the gap's rows at q
    e_gap = 0; e_old = 0; maxlever = 0
    do k = 1, c%set%nact
      e_gap = max(e_gap, row_error(c, c%set%act(k), q, .false.))
      old = c%set%act(k); old%nl = 0   ! (the row without the lever)
      e_old = max(e_old, row_error(c, old, q, .false.))
      maxlever = max(maxlever, real(c%set%act(k)%nl, dp))
    end do
    call check_true(label//': every constraint has its lever', all(c%set%act(1:c%set%nact)%nl >= 10))
    call check_le(label//': gap row against finite differences', e_gap, 1e-6_dp)
    if (label /= 'rim') call check_curvature(c, label)
    call check_le(label//': (without the lever, the error is large) 1 /', 1/e_old, 10._dp)
    ! the force's rows at the midpoint of q and qn
    call contact_force_points(c, model, 0.5_dp, qn, q)
    qf = 0.5_dp*(q + qn)
    e_force = 0; mom = 0
    do k = 1, c%set%nact
      e_force = max(e_force, row_error(c, c%set%act(k), qf, .true.))
      mom = max(mom, moment(c%set%act(k), qf))
    end do
    call check_le(label//': force row at the midpoint against finite differences', e_force, 1e-6_dp)
    call check_le(label//': force row: net force and moment at the midpoint', mom, 1e-10_dp)
  end subroutine check_rows

  !> The blade's rim nodes in the offset's fade band: the gap's second derivative along n on
  !> the node's fibre, -wgg (the bend row's stiffness over -lambda), against central second
  !> differences (step 1e-5 on the fibre: truncation and round-off below 1e-6 of wgg)
  subroutine check_curvature(c, label)
    type(contact_t), intent(in) :: c
    character(len=*), intent(in) :: label
    real(dp), parameter :: h = 1e-5_dp
    real(dp), allocatable :: qp(:)
    real(dp) :: fd, e, scale
    integer :: k, nband, n
    e = 0; scale = 0; nband = 0
    do k = 1, c%set%nact
      associate (a => c%set%act(k))
        if (a%wgg == 0) cycle
        nband = nband + 1
        n = a%node
        qp = q
        qp(dof(n, 4):dof(n, 6)) = q(dof(n, 4):dof(n, 6)) + h*a%n
        fd = gap_at(c, a, qp)
        qp(dof(n, 4):dof(n, 6)) = q(dof(n, 4):dof(n, 6)) - h*a%n
        fd = (fd - 2*gap_at(c, a, q) + gap_at(c, a, qp))/h**2
        e = max(e, abs(fd + a%wgg)); scale = max(scale, abs(a%wgg))
      end associate
    end do
    call check_true(label//': rim nodes in the fade band ('//itoa(nband)//')', nband >= 4)
    if (nband > 0) call check_le(label//': the offset''s curvature on the fibre against second differences', &
                                 e/scale, 1e-4_dp)
  end subroutine check_curvature

  !> largest |row - finite difference| over the largest |finite difference| of con's gap at qa
  real(dp) function row_error(c, con, qa, force) result(err)
    type(contact_t), intent(in) :: c
    type(constraint_t), intent(in) :: con
    real(dp), intent(in) :: qa(:)
    logical, intent(in) :: force
    real(dp), parameter :: h = 1e-7_dp
    real(dp), allocatable :: row(:), fd(:), qp(:)
    real(dp) :: v(max_row)
    integer :: d(max_row), nd, i
    allocate (row(model%ndof), fd(model%ndof))
    row = 0
    call constraint_row(con, model, d, v, nd, 0, force)
    do i = 1, nd
      row(d(i)) = row(d(i)) + v(i)
    end do
    qp = qa
    do i = 1, model%ndof
      qp(i) = qa(i) + h
      fd(i) = gap_at(c, con, qp)
      qp(i) = qa(i) - h
      fd(i) = (fd(i) - gap_at(c, con, qp))/(2*h)
      qp(i) = qa(i)
    end do
    err = maxval(abs(row - fd))/maxval(abs(fd))
  end function row_error

  !> con's gap at qa, its point, side and faces held
  real(dp) function gap_at(c, con, qa)
    type(contact_t), intent(in) :: c
    type(constraint_t), intent(in) :: con
    real(dp), intent(in) :: qa(:)
    type(constraint_t) :: cp
    cp = con
    call constraint_geometry(c, model, positions(model, qa), qa, cp)   ! (the gap only)
    gap_at = cp%gap
  end function gap_at

  !> |net force| + |moment about the origin| of con's force row at qa (positions and fibres),
  !> over the row's size
  real(dp) function moment(con, qa)
    type(constraint_t), intent(in) :: con
    real(dp), intent(in) :: qa(:)
    real(dp) :: v(max_row), f(3), m(3), e(3)
    integer :: d(max_row), nd, i, n, comp, kind
    call constraint_row(con, model, d, v, nd, 0, .true.)
    f = 0; m = 0
    do i = 1, nd
      n = (d(i) - 1)/(dof(2, 1) - dof(1, 1)) + 1   ! (node and component: d = dof(n, comp))
      comp = d(i) - dof(n, 1) + 1
      if (comp > 6) cycle
      kind = (comp - 1)/3
      e = 0; e(comp - 3*kind) = v(i)
      if (kind == 0) f = f + e
      m = m + cross(qa(dof(n, 3*kind + 1):dof(n, 3*kind + 3)), e)
    end do
    moment = (norm2(f) + norm2(m))/maxval(abs(v(1:nd)))
  end function moment

  function itoa(i) result(s)
    integer, intent(in) :: i
    character(len=:), allocatable :: s
    character(len=12) :: b
    write (b, '(i0)') i
    s = trim(b)
  end function itoa
end program test_contact_lever
