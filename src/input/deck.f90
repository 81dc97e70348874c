!> The input deck: a Fortran namelist file with the groups
!>   &run        analysis (dynamic, static, linear), time step, end time, Newmark and Newton
!>               parameters, gravity
!>   &output     folder, frame interval, tracked points, checkpoint interval
!>   &body       (one per body) mesh or generator, material, thickness, initial motion
!>   &restraint  (any number) prescribed parameters of a body's nodes: a box, a node list or
!>               a named set (a physical group of the body's mesh file)
!>   &load       (any number) a dead force and a moment on a body's nodes (box, list or set):
!>               shared equally ('nodal') or a uniform line load on the selected boundary edge
!>               ('edge'); or a follower pressure on the elements whose nodes are all selected
!>               ('pressure')
!>   &contact    contact pairs, surfaces and tolerances
!>   &obstacle   (any number) a rigid plane, sphere or cylinder, fixed or moving
!> Every problem found while reading is collected (file:line: group: message) so that the
!> user sees them all at once; nothing here stops the program.
module casca_deck
  use, intrinsic :: iso_fortran_env, only: iostat_end, iostat_eor
  use casca_files, only: file_kind, kind_special, kind_folder
  use casca_kinds, only: dp
  use casca_strings, only: itoa
  use casca_deck_lint, only: lint_group, outside_text, lower
  implicit none
  private
  public :: deck_t, run_cfg_t, output_cfg_t, body_cfg_t, restraint_cfg_t, load_cfg_t
  public :: contact_cfg_t, obstacle_cfg_t, read_deck, add_problem, max_track, unset, deck_file, default_newton_tol
  public :: counts_for_size, frame_interval

  integer, parameter :: max_track = 16
  integer, parameter :: max_pairs = 64
  integer, parameter :: max_set = 512            !< nodes listed in one restraint or load
  !> Strings are read into buffers this long and refused if longer than their field (a name
  !> cut short would silently name another folder or body); lines longer than max_line_len
  !> are refused (the checks of deck_lint would read them cut).
  integer, parameter :: long = 1024
  integer, parameter :: max_line_len = 4096
  real(dp), parameter :: unset = -huge(1._dp)   !< marks a value the deck did not give
  real(dp), parameter :: default_newton_tol = 1e-9_dp   !< &run newton_tol when neither it nor tolerance is given
  character(len=*), parameter :: known_groups(8) = &
    [character(len=9) :: 'run', 'output', 'body', 'restraint', 'load', 'contact', 'obstacle', 'end']

  type :: run_cfg_t
    character(len=128) :: title = ''
    character(len=16) :: analysis = 'dynamic'   !< 'dynamic' or 'static' (also for 'linear')
    logical :: linear = .false.                 !< analysis = 'linear': statics at small
                                                !< displacements, one solve at the whole load
    real(dp) :: dt = unset, t_end = unset
    real(dp) :: beta = 1.0_dp, gamma = 1.5_dp  !< the thesis' choice for impact
    real(dp) :: rho_inf = unset                 !< given: generalized-alpha (not beta, gamma)
    real(dp) :: tolerance = unset               !< given: steps chosen by the local error
    real(dp) :: tolerance_length = unset        !< what tolerance is relative to (scene size)
    real(dp) :: newton_tol = unset              !< not given: default_newton_tol, or from tolerance
    integer :: newton_max_iter = 20
    integer :: load_steps = 10
    integer :: max_step_cuts = 4
    logical :: reuse_factorisation = .true.     !< modified Newton while it contracts fast
    logical :: skip_idle_bodies = .true.        !< advance bodies in free flight without solving
    logical :: load_stiffness = .true.          !< the follower pressures' load stiffness in Newton
    real(dp) :: gravity(3) = 0
    character(len=16) :: ordering = 'auto'      !< 'auto' (MUMPS) or 'metis'
    character(len=16) :: factor_precision = 'double'   !< K's factors: 'double' or 'single'
    integer :: line = 0
  end type run_cfg_t

  type :: output_cfg_t
    character(len=256) :: dir = 'out'
    real(dp) :: interval = unset                !< time between VTU frames (default t_end/100)
    logical :: vtu = .true.
    logical :: plots = .true.
    real(dp) :: checkpoint_interval = 0         !< 0: checkpoint at the end only
    integer :: ntrack = 0
    real(dp) :: track(3, max_track) = 0         !< tracked nodes: nearest to these points
    character(len=64) :: track_body(max_track) = ''
    integer :: line = 0
  end type output_cfg_t

  type :: body_cfg_t
    character(len=64) :: name = ''
    character(len=16) :: mesh = ''              !< ring, sphere, plate, strip, file
    character(len=256) :: file = ''
    real(dp) :: radius = 1, width = 0.2_dp, lx = 1, ly = 1
    integer :: n_around = 20, n_across = 1, n_div = 6, nx = 4, ny = 1
    real(dp) :: rotate_axis(3) = [0, 0, 1]      !< the mesh is first rotated about this axis ...
    real(dp) :: rotate_angle = 0                !< ... by this angle [degrees]
    real(dp) :: center(3) = 0                   !< ... and then moved by this vector
    real(dp) :: young = unset, poisson = 0.3_dp, density = unset, thickness = unset
    real(dp) :: velocity(3) = 0, omega(3) = 0   !< omega about the body's centroid
    real(dp) :: gravity(3) = 0                  !< the body's own, added to &run's
    logical :: flip_normals = .false.           !< reverse the elements' orientation
    real(dp) :: element_size = unset            !< given: the generator's counts from it [m]
    integer :: line = 0
  end type body_cfg_t

  type :: restraint_cfg_t
    character(len=64) :: body = ''
    real(dp) :: box_min(3) = -huge(1._dp), box_max(3) = huge(1._dp)
    integer, allocatable :: nodes(:)            !< node numbers in the body (a node list)
    character(len=64) :: set = ''               !< a physical group of the body's mesh file
    character(len=64) :: fix = 'clamped'
    integer :: line = 0
  end type restraint_cfg_t

  type :: load_cfg_t
    character(len=64) :: body = ''
    real(dp) :: box_min(3) = -huge(1._dp), box_max(3) = huge(1._dp)
    integer, allocatable :: nodes(:)            !< node numbers in the body (a node list)
    character(len=64) :: set = ''               !< a physical group of the body's mesh file
    character(len=16) :: kind = 'nodal'         !< 'nodal': shared equally; 'edge': line load
    real(dp) :: force(3) = 0                    !< total
    real(dp) :: moment(3) = 0                   !< total [N m], about a fixed axis
    real(dp) :: pressure = 0                    !< kind 'pressure' [Pa], along the normal
    integer :: line = 0
  end type load_cfg_t

  type :: contact_cfg_t
    logical :: enabled = .true.
    integer :: npairs = 0                       !< 0: every pair of bodies
    character(len=64) :: pairs(2, max_pairs) = ''
    real(dp) :: tolerance = 1e-7_dp             !< penetration accepted, relative to scene size
    real(dp) :: stiffness = unset               !< compliant contact [Pa/m]; unset: hard
    character(len=16) :: solver = 'auto'        !< 'auto', 'schur' or 'saddle' (docs/method.md)
    character(len=16) :: normal = 'nodal'       !< 'nodal' or 'element' (docs/method.md)
    character(len=16) :: surface = 'faces'      !< 'faces' (thickness offset) or 'mid'
    integer :: passes = 1                       !< 2: each body of a pair impacts the other too
    real(dp) :: friction = 0                    !< Coulomb: dynamic coefficient
    real(dp) :: static_friction = unset         !< static coefficient (default: friction)
    !> per listed pair (pairs(:, k)): its own coefficients (default: the two above)
    real(dp) :: pair_friction(max_pairs) = unset, pair_static_friction(max_pairs) = unset
    !> decay of the sliding coefficient with the slip speed, LS-DYNA's DC [s/m] (unset: from
    !> static to dynamic at once); per listed pair its own (default &contact's)
    real(dp) :: friction_decay = unset, pair_friction_decay(max_pairs) = unset
    integer :: line = 0
  end type contact_cfg_t

  type :: obstacle_cfg_t
    character(len=64) :: name = ''
    character(len=16) :: shape = ''             !< plane, sphere, cylinder
    real(dp) :: point(3) = 0                    !< plane: a point; sphere: centre; cylinder: on the axis
    real(dp) :: normal(3) = 0                   !< plane: towards the bodies
    real(dp) :: axis(3) = 0                     !< cylinder
    real(dp) :: radius = unset
    logical :: inside = .false.                 !< sphere, cylinder: the bodies are inside
    real(dp) :: velocity(3) = 0
    real(dp) :: friction = unset, static_friction = unset   !< (default: &contact's)
    real(dp) :: friction_decay = unset          !< (default: &contact's)
    integer :: nbodies = 0                      !< 0: every body
    character(len=64) :: bodies(max_pairs) = ''
    integer :: line = 0
  end type obstacle_cfg_t

  type :: deck_t
    character(len=:), allocatable :: path
    character(len=:), allocatable :: base_dir   !< folder of the deck: mesh files are relative to it
    type(run_cfg_t) :: run
    type(output_cfg_t) :: output
    type(body_cfg_t), allocatable :: bodies(:)
    type(restraint_cfg_t), allocatable :: restraints(:)
    type(load_cfg_t), allocatable :: loads(:)
    type(contact_cfg_t) :: contact
    type(obstacle_cfg_t), allocatable :: obstacles(:)
    integer :: nproblems = 0
    character(len=512), allocatable :: problems(:)
    !> of the problems, those that leave the rest of the deck readable (a misspelt group name,
    !> the group left out; a contradiction between values read): the other groups are still
    !> read and their values checked, so that one slip does not hide the other problems
    integer :: readable_problems = 0
    !> each key given in a group, with the line of its group and its own line: a problem
    !> found in a value is reported at the key's line (add_problem)
    character(len=20), allocatable :: key_name(:)
    integer, allocatable :: key_group_line(:), key_line(:)
  end type deck_t

contains

  !> The time between frames of a dynamic run: &output interval (t_end/100 when not given),
  !> at least one step dt
  pure real(dp) function frame_interval(deck) result(interval)
    type(deck_t), intent(in) :: deck
    interval = deck%output%interval
    if (interval == unset) interval = deck%run%t_end/100
    interval = max(interval, deck%run%dt)
  end function frame_interval

  !> A file named in the deck: relative names are relative to the deck's folder.
  function deck_file(deck, name) result(path)
    type(deck_t), intent(in) :: deck
    character(len=*), intent(in) :: name
    character(len=:), allocatable :: path
    if (name(1:1) == '/') then
      path = trim(name)
    else
      path = deck%base_dir//trim(name)
    end if
  end function deck_file

  !> A problem of the deck at line (0: of the deck as a whole). A message about a value,
  !> '&group [name]: key ...' given a group's first line, is moved to that key's line.
  subroutine add_problem(deck, line_given, msg)
    type(deck_t), intent(inout) :: deck
    integer, intent(in) :: line_given
    character(len=*), intent(in) :: msg
    character(len=512) :: text
    integer :: line
    line = key_line_of(deck, line_given, msg)
    if (line > 0) then
      text = deck%path//':'//itoa(line)//': '//msg
    else
      text = deck%path//': '//msg
    end if
    if (.not. allocated(deck%problems)) allocate (deck%problems(0))
    deck%problems = [deck%problems, text]
    deck%nproblems = size(deck%problems)
  end subroutine add_problem

  !> The line of the key a message names after its group ('&body a: poisson must ...'), if
  !> line is the first line of a group that gave that key; else line
  pure integer function key_line_of(deck, line, msg) result(at)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: line
    character(len=*), intent(in) :: msg
    integer :: i, j, k
    at = line
    if (line <= 0 .or. .not. allocated(deck%key_name) .or. msg(1:min(1, len(msg))) /= '&') return
    i = index(msg, ': ')
    if (i == 0) return
    j = i + 2
    k = verify(msg(j:), 'abcdefghijklmnopqrstuvwxyz0123456789_')
    if (k == 1) return
    if (k == 0) k = len(msg) - j + 2
    do i = 1, size(deck%key_name)
      if (deck%key_group_line(i) == line .and. deck%key_name(i) == msg(j:j + k - 2)) then
        at = deck%key_line(i); return
      end if
    end do
  end function key_line_of

  !> dest = text, or a problem naming the field if text does not fit in dest
  subroutine take(deck, line, field, text, dest)
    type(deck_t), intent(inout) :: deck
    integer, intent(in) :: line
    character(len=*), intent(in) :: field, text
    character(len=*), intent(inout) :: dest
    character(len=16) :: n
    if (len_trim(text) > len(dest)) then
      write (n, '(i0)') len(dest)
      call add_problem(deck, line, field//' is longer than '//trim(n)//' characters ("'// &
                       text(1:20)//'...")')
    else
      dest = text
    end if
  end subroutine take

  !> Read every group of the deck at path. Problems go to deck%problems.
  subroutine read_deck(path, deck)
    character(len=*), intent(in) :: path
    type(deck_t), intent(out) :: deck
    integer :: u, ios, k
    character(len=256) :: msg
    integer, allocatable :: gline(:)
    character(len=16), allocatable :: gname(:)

    deck%path = path
    k = index(path, '/', back=.true.)
    deck%base_dir = path(1:k)
    allocate (deck%bodies(0), deck%restraints(0), deck%loads(0), deck%obstacles(0))
    if (file_kind(path) == kind_special .or. file_kind(path) == kind_folder) then
      call add_problem(deck, 0, 'the deck is not a regular file (a folder, FIFO or device)')
      return
    end if
    open (newunit=u, file=path, status='old', action='read', iostat=ios, iomsg=msg)
    if (ios /= 0) then
      call add_problem(deck, 0, 'cannot open the deck: '//trim(msg))
      return
    end if
    call scan_groups(u, deck, gname, gline)
    if (deck%nproblems > deck%readable_problems) then
      close (u); return
    end if
    call read_run(u, deck, line_of('run', 1))
    call read_output(u, deck, line_of('output', 1))
    call read_contact(u, deck, line_of('contact', 1))
    call read_bodies(u, deck)
    call read_restraints(u, deck)
    call read_loads(u, deck)
    call read_obstacles(u, deck)
    close (u)
    if (count(gname == 'run') > 1) call add_problem(deck, line_of('run', 2), '&run given twice')
    if (count(gname == 'output') > 1) &
      call add_problem(deck, line_of('output', 2), '&output given twice')
    if (count(gname == 'contact') > 1) &
      call add_problem(deck, line_of('contact', 2), '&contact given twice')
    if (count(gname == 'run') == 0) call add_problem(deck, 0, 'no &run group')
    if (count(gname == 'body') == 0) call add_problem(deck, 0, 'no &body group')
  contains
    !> line of the k-th group called name (0 if there is none)
    integer function line_of(name, kth)
      character(len=*), intent(in) :: name
      integer, intent(in) :: kth
      integer :: i, c
      line_of = 0; c = 0
      do i = 1, size(gname)
        if (gname(i) == name) then
          c = c + 1
          if (c == kth) then
            line_of = gline(i); return
          end if
        end if
      end do
    end function line_of

    subroutine read_bodies(uu, dk)
      integer, intent(in) :: uu
      type(deck_t), intent(inout) :: dk
      character(len=long) :: name, mesh, file
      real(dp) :: radius, width, lx, ly, center(3), young, poisson, density, thickness
      real(dp) :: rotate_axis(3), rotate_angle
      real(dp) :: velocity(3), omega(3), gravity(3), element_size
      integer :: n_around, n_across, n_div, nx, ny, ib
      logical :: flip_normals
      namelist /body/ name, mesh, file, radius, width, lx, ly, n_around, n_across, n_div, &
        nx, ny, center, rotate_axis, rotate_angle, young, poisson, density, thickness, velocity, omega, &
        gravity, flip_normals, element_size
      type(body_cfg_t) :: b
      rewind (uu)
      do ib = 1, count(gname == 'body')
        b = body_cfg_t()
        name = b%name; mesh = b%mesh; file = b%file; radius = b%radius; width = b%width
        lx = b%lx; ly = b%ly; n_around = b%n_around; n_across = b%n_across; n_div = b%n_div
        nx = b%nx; ny = b%ny; center = b%center; young = b%young; poisson = b%poisson
        density = b%density; thickness = b%thickness; velocity = b%velocity; omega = b%omega
        rotate_axis = b%rotate_axis; rotate_angle = b%rotate_angle; gravity = b%gravity
        flip_normals = b%flip_normals; element_size = b%element_size
        read (uu, nml=body, iostat=ios, iomsg=msg)
        if (ios /= 0) then
          call add_problem(dk, line_of('body', ib), '&body: '//trim(msg))
          return
        end if
        b%line = line_of('body', ib)
        call take(dk, b%line, '&body: name', name, b%name)
        call take(dk, b%line, '&body: mesh', mesh, b%mesh)
        call take(dk, b%line, '&body: file', file, b%file)
        b%radius = radius; b%width = width
        b%lx = lx; b%ly = ly; b%n_around = n_around; b%n_across = n_across; b%n_div = n_div
        b%nx = nx; b%ny = ny; b%center = center; b%young = young; b%poisson = poisson
        b%density = density; b%thickness = thickness; b%velocity = velocity; b%omega = omega
        b%rotate_axis = rotate_axis; b%rotate_angle = rotate_angle; b%gravity = gravity
        b%flip_normals = flip_normals; b%element_size = element_size
        if (element_size /= unset) call counts_for_size(b)
        dk%bodies = [dk%bodies, b]
      end do
    end subroutine read_bodies

    subroutine read_restraints(uu, dk)
      integer, intent(in) :: uu
      type(deck_t), intent(inout) :: dk
      character(len=long) :: body, fix, set
      real(dp) :: box_min(3), box_max(3)
      integer :: nodes(max_set)
      namelist /restraint/ body, box_min, box_max, fix, nodes, set
      type(restraint_cfg_t) :: r
      integer :: ir
      rewind (uu)
      do ir = 1, count(gname == 'restraint')
        r = restraint_cfg_t()
        body = r%body; fix = r%fix; box_min = r%box_min; box_max = r%box_max; nodes = 0
        set = r%set
        read (uu, nml=restraint, iostat=ios, iomsg=msg)
        if (ios /= 0) then
          call add_problem(dk, line_of('restraint', ir), '&restraint: '//trim(msg))
          return
        end if
        r%line = line_of('restraint', ir)
        call take(dk, r%line, '&restraint: body', body, r%body)
        call take(dk, r%line, '&restraint: fix', fix, r%fix)
        call take(dk, r%line, '&restraint: set', set, r%set)
        r%box_min = box_min; r%box_max = box_max
        r%nodes = pack(nodes, nodes /= 0)
        dk%restraints = [dk%restraints, r]
      end do
    end subroutine read_restraints

    subroutine read_loads(uu, dk)
      integer, intent(in) :: uu
      type(deck_t), intent(inout) :: dk
      character(len=long) :: body, set, kind
      real(dp) :: box_min(3), box_max(3), force(3), moment(3), pressure
      integer :: nodes(max_set)
      namelist /load/ body, box_min, box_max, force, moment, nodes, set, kind, pressure
      type(load_cfg_t) :: l
      integer :: il
      rewind (uu)
      do il = 1, count(gname == 'load')
        l = load_cfg_t()
        body = l%body; box_min = l%box_min; box_max = l%box_max; force = l%force; nodes = 0
        moment = l%moment
        set = l%set; kind = l%kind; pressure = l%pressure
        read (uu, nml=load, iostat=ios, iomsg=msg)
        if (ios /= 0) then
          call add_problem(dk, line_of('load', il), '&load: '//trim(msg))
          return
        end if
        l%line = line_of('load', il)
        call take(dk, l%line, '&load: body', body, l%body)
        call take(dk, l%line, '&load: set', set, l%set)
        call take(dk, l%line, '&load: kind', lower(kind), l%kind)
        l%box_min = box_min; l%box_max = box_max; l%force = force; l%pressure = pressure
        l%moment = moment
        l%nodes = pack(nodes, nodes /= 0)
        dk%loads = [dk%loads, l]
      end do
    end subroutine read_loads

    subroutine read_obstacles(uu, dk)
      integer, intent(in) :: uu
      type(deck_t), intent(inout) :: dk
      character(len=long) :: name, shape
      character(len=256) :: bodies(max_pairs)
      real(dp) :: point(3), normal(3), axis(3), radius, velocity(3), friction, static_friction
      real(dp) :: friction_decay
      logical :: inside
      namelist /obstacle/ name, shape, point, normal, axis, radius, inside, velocity, bodies, &
        friction, static_friction, friction_decay
      type(obstacle_cfg_t) :: o
      integer :: io, k
      rewind (uu)
      do io = 1, count(gname == 'obstacle')
        o = obstacle_cfg_t()
        name = o%name; shape = o%shape; point = o%point; normal = o%normal; axis = o%axis
        radius = o%radius; inside = o%inside; velocity = o%velocity; bodies = ''
        friction = o%friction; static_friction = o%static_friction; friction_decay = o%friction_decay
        read (uu, nml=obstacle, iostat=ios, iomsg=msg)
        if (ios /= 0) then
          call add_problem(dk, line_of('obstacle', io), '&obstacle: '//trim(msg))
          return
        end if
        o%line = line_of('obstacle', io)
        call take(dk, o%line, '&obstacle: name', name, o%name)
        call take(dk, o%line, '&obstacle: shape', lower(shape), o%shape)
        o%point = point; o%normal = normal; o%axis = axis; o%radius = radius
        o%inside = inside; o%velocity = velocity
        o%friction = friction; o%static_friction = static_friction; o%friction_decay = friction_decay
        do k = 1, max_pairs
          if (bodies(k) == '') exit
          o%nbodies = k
          call take(dk, o%line, '&obstacle: bodies', bodies(k), o%bodies(k))
        end do
        dk%obstacles = [dk%obstacles, o]
      end do
    end subroutine read_obstacles
  end subroutine read_deck

  !> Names and lines of every '&group' in the file; unknown names are problems (a misspelt
  !> group would otherwise be skipped silently by the namelist reader).
  subroutine scan_groups(u, deck, gname, gline)
    integer, intent(inout) :: u   !< the deck; a scratch copy without its unknown keys if any
    type(deck_t), intent(inout) :: deck
    character(len=16), allocatable, intent(out) :: gname(:)
    integer, allocatable, intent(out) :: gline(:)
    character(len=max_line_len) :: line
    character(len=max_line_len), allocatable :: text(:)
    character(len=16) :: name
    integer :: ios, n, j, k, nread, readable
    integer, allocatable :: lines(:), key_lines(:)
    character(len=512), allocatable :: msgs(:)
    character(len=20), allocatable :: keys(:)

    allocate (gname(0), gline(0), text(0))
    n = 0
    do
      read (u, '(a)', advance='no', size=nread, iostat=ios) line
      if (ios == iostat_end) exit
      if (ios == 0) then   ! no end of line within the buffer
        write (name, '(i0)') max_line_len
        call add_problem(deck, n + 1, 'line longer than '//trim(name)//' characters')
        read (u, '(a)', iostat=ios)   ! (the rest of it)
      else if (ios /= iostat_eor) then
        call add_problem(deck, n + 1, 'unreadable line'); exit
      end if
      n = n + 1
      ! (a byte-order mark before the first group hides it from the namelist read)
      if (n == 1 .and. line(1:3) == achar(239)//achar(187)//achar(191)) then
        call add_problem(deck, 1, 'the deck starts with a UTF-8 byte-order mark (an editor''s '// &
          '"UTF-8 with BOM"), which hides its first group: save it as UTF-8 without BOM, or ASCII')
        line(1:3) = ''
      end if
      text = [character(len=max_line_len) :: text, line]
      line = adjustl(line)
      if (line(1:1) /= '&') cycle
      j = scan(line(2:), ' /,'//achar(9))
      if (j == 0) j = len_trim(line)
      name = lower(line(2:j))
      if (all(known_groups /= name)) then
        call add_problem(deck, n, 'unknown group &'//trim(name)// &
                         ' (known: &run, &output, &body, &restraint, &load, &contact, &obstacle)')
        deck%readable_problems = deck%readable_problems + 1
        cycle
      end if
      if (name == 'end') cycle
      gname = [character(len=16) :: gname, name]; gline = [gline, n]
    end do
    rewind (u)
    ! (the namelist read skips such text: the rest of the deck reads as it would without it)
    call outside_text(text, lines, msgs)
    do j = 1, size(lines)
      call add_problem(deck, lines(j), trim(msgs(j)))
    end do
    deck%readable_problems = deck%readable_problems + size(lines)
    allocate (deck%key_name(0), deck%key_group_line(0), deck%key_line(0))
    do k = 1, size(gname)
      call lint_group(text, gline(k), trim(gname(k)), lines, msgs, keys, key_lines, readable)
      do j = 1, size(lines)
        call add_problem(deck, lines(j), trim(msgs(j)))
      end do
      deck%readable_problems = deck%readable_problems + readable
      deck%key_name = [character(len=20) :: deck%key_name, keys]
      deck%key_group_line = [deck%key_group_line, spread(gline(k), 1, size(keys))]
      deck%key_line = [deck%key_line, key_lines]
    end do
    if (deck%readable_problems == 0 .or. deck%nproblems > deck%readable_problems) return
    ! (the groups are read from the text without its unknown keys, line for line)
    close (u)
    open (newunit=u, status='scratch', action='readwrite', iostat=ios)
    if (ios /= 0) then
      call add_problem(deck, 0, 'cannot open a scratch file to read the deck without its unknown keys')
      return
    end if
    do k = 1, size(text)
      write (u, '(a)') trim(text(k))
    end do
    rewind (u)
  end subroutine scan_groups

  subroutine read_run(u, deck, line)
    integer, intent(in) :: u, line
    type(deck_t), intent(inout) :: deck
    character(len=long) :: title, analysis, ordering, factor_precision
    real(dp) :: dt, t_end, beta, gamma, rho_inf, tolerance, tolerance_length, newton_tol, gravity(3)
    integer :: newton_max_iter, load_steps, max_step_cuts, ios
    logical :: reuse_factorisation, skip_idle_bodies, load_stiffness
    character(len=256) :: msg
    namelist /run/ title, analysis, dt, t_end, beta, gamma, rho_inf, tolerance, tolerance_length, &
      newton_tol, newton_max_iter, load_steps, max_step_cuts, gravity, ordering, factor_precision, &
      reuse_factorisation, skip_idle_bodies, load_stiffness
    associate (c => deck%run)
      ! (beta and gamma read as unset: given with rho_inf they are refused, not overridden)
      title = c%title; analysis = c%analysis; dt = c%dt; t_end = c%t_end; beta = unset
      gamma = unset; rho_inf = c%rho_inf; tolerance = c%tolerance
      tolerance_length = c%tolerance_length; newton_tol = c%newton_tol; newton_max_iter = c%newton_max_iter
      load_steps = c%load_steps; max_step_cuts = c%max_step_cuts; gravity = c%gravity
      ordering = c%ordering; factor_precision = c%factor_precision
      reuse_factorisation = c%reuse_factorisation
      skip_idle_bodies = c%skip_idle_bodies
      load_stiffness = c%load_stiffness
      c%line = line
      if (line == 0) return
      rewind (u)
      read (u, nml=run, iostat=ios, iomsg=msg)
      if (ios /= 0) then
        call add_problem(deck, line, '&run: '//trim(msg)); return
      end if
      call take(deck, line, '&run: title', title, c%title)
      call take(deck, line, '&run: analysis', lower(analysis), c%analysis)
      if (c%analysis == 'linear') then   ! (a static run in every other respect)
        c%analysis = 'static'; c%linear = .true.
      end if
      call take(deck, line, '&run: ordering', lower(ordering), c%ordering)
      call take(deck, line, '&run: factor_precision', lower(factor_precision), c%factor_precision)
      c%dt = dt; c%t_end = t_end; c%rho_inf = rho_inf
      c%tolerance = tolerance; c%tolerance_length = tolerance_length
      if (rho_inf /= unset .and. (beta /= unset .or. gamma /= unset)) then
        call add_problem(deck, line, &
          '&run: rho_inf (generalized-alpha) is given with beta or gamma (Newmark): give one or the other')
        deck%readable_problems = deck%readable_problems + 1
      end if
      if (beta /= unset) c%beta = beta
      if (gamma /= unset) c%gamma = gamma
      ! an error asked for and no scheme named: a second-order one, whose local error falls as
      ! dt^3 where the thesis' Newmark's falls as dt^2 (and which keeps the energy)
      if (tolerance /= unset .and. all([rho_inf, beta, gamma] == unset)) c%rho_inf = 0.8_dp
      c%newton_tol = newton_tol; c%newton_max_iter = newton_max_iter
      c%load_steps = load_steps; c%max_step_cuts = max_step_cuts; c%gravity = gravity
      c%reuse_factorisation = reuse_factorisation
      c%skip_idle_bodies = skip_idle_bodies
      c%load_stiffness = load_stiffness
    end associate
  end subroutine read_run

  subroutine read_output(u, deck, line)
    integer, intent(in) :: u, line
    type(deck_t), intent(inout) :: deck
    character(len=long) :: dir, track_body(max_track)
    character(len=256) :: msg
    real(dp) :: interval, checkpoint_interval, track(3, max_track)
    logical :: vtu, plots
    integer :: ios, k
    namelist /output/ dir, interval, vtu, plots, checkpoint_interval, track, track_body
    associate (c => deck%output)
      dir = c%dir; interval = c%interval; vtu = c%vtu; plots = c%plots
      checkpoint_interval = c%checkpoint_interval
      track = unset; track_body = ''
      c%line = line
      c%track = track   ! (no point tracked, even with no &output group: sanity.f90 reads it)
      if (line == 0) return
      rewind (u)
      read (u, nml=output, iostat=ios, iomsg=msg)
      if (ios /= 0) then
        call add_problem(deck, line, '&output: '//trim(msg)); return
      end if
      call take(deck, line, '&output: dir', dir, c%dir)
      do k = 1, max_track
        call take(deck, line, '&output: track_body', track_body(k), c%track_body(k))
      end do
      c%interval = interval; c%vtu = vtu; c%plots = plots
      c%checkpoint_interval = checkpoint_interval
      c%ntrack = 0
      do k = 1, max_track
        if (any(track(:, k) == unset)) exit
        c%ntrack = k
      end do
      c%track = track   ! (a point short of a coordinate: sanity.f90)
    end associate
  end subroutine read_output

  subroutine read_contact(u, deck, line)
    integer, intent(in) :: u, line
    type(deck_t), intent(inout) :: deck
    logical :: enabled
    character(len=long) :: solver, normal, surface
    character(len=256) :: pairs(2, max_pairs)   ! (longer than a name: enough to see one too long)
    real(dp) :: tolerance, friction, static_friction, stiffness, friction_decay
    real(dp) :: pair_friction(max_pairs), pair_static_friction(max_pairs), pair_friction_decay(max_pairs)
    character(len=256) :: msg
    integer :: ios, k, passes
    namelist /contact/ enabled, pairs, tolerance, solver, normal, surface, passes, friction, &
      static_friction, pair_friction, pair_static_friction, stiffness, friction_decay, pair_friction_decay
    associate (c => deck%contact)
      enabled = c%enabled; pairs = ''; tolerance = c%tolerance; solver = c%solver; normal = c%normal
      stiffness = c%stiffness
      surface = c%surface; passes = c%passes; friction = c%friction; static_friction = c%static_friction
      pair_friction = c%pair_friction; pair_static_friction = c%pair_static_friction
      friction_decay = c%friction_decay; pair_friction_decay = c%pair_friction_decay
      c%line = line
      if (line == 0) return
      rewind (u)
      read (u, nml=contact, iostat=ios, iomsg=msg)
      if (ios /= 0) then
        call add_problem(deck, line, '&contact: '//trim(msg)); return
      end if
      c%enabled = enabled; c%tolerance = tolerance; c%stiffness = stiffness
      call take(deck, line, '&contact: solver', lower(solver), c%solver)
      call take(deck, line, '&contact: normal', lower(normal), c%normal)
      call take(deck, line, '&contact: surface', lower(surface), c%surface)
      c%passes = passes; c%friction = friction; c%static_friction = static_friction
      c%pair_friction = pair_friction; c%pair_static_friction = pair_static_friction
      c%friction_decay = friction_decay; c%pair_friction_decay = pair_friction_decay
      c%npairs = 0
      do k = 1, max_pairs
        if (pairs(1, k) == '' .and. pairs(2, k) == '') exit
        c%npairs = k
        call take(deck, line, '&contact: pairs', pairs(1, k), c%pairs(1, k))
        call take(deck, line, '&contact: pairs', pairs(2, k), c%pairs(2, k))
        if (pairs(1, k) == '' .or. pairs(2, k) == '') &
          call add_problem(deck, line, '&contact: pairs needs two body names per pair')
      end do
    end associate
  end subroutine read_contact

  !> A generator's counts for elements of about b%element_size along their edges (at least
  !> that fine): ring 2 pi R / size around and width / size across, sphere the icosahedron's
  !> edge (1.0515 R) / size per face edge, plate lx / size by ly / size. Left as they are when
  !> a size is not positive and finite (the sanity check says so); at most 10^6 per direction
  !> (the check of the element count refuses the rest).
  pure subroutine counts_for_size(b)
    type(body_cfg_t), intent(inout) :: b
    if (.not. (b%element_size > 0 .and. b%element_size < huge(1._dp))) return
    select case (b%mesh)
    case ('ring')
      b%n_around = max(3, cells(2*acos(-1._dp)*b%radius))
      b%n_across = cells(b%width)
    case ('sphere')
      b%n_div = cells(b%radius/sin(0.4_dp*acos(-1._dp)))
    case ('plate', 'strip')
      b%nx = cells(b%lx); b%ny = cells(b%ly)
    end select
  contains
    pure integer function cells(length)
      real(dp), intent(in) :: length
      cells = 1
      if (length > 0) cells = int(min(1e6_dp, max(1._dp, real(ceiling(min(length/b%element_size, &
                                  1e6_dp)), dp))))
    end function cells
  end subroutine counts_for_size
end module casca_deck
