!> Checks of a deck's values before any work (CaNS's sanity module): every problem is added
!> to deck%problems with the deck's file name, the group's line and the field.
module casca_sanity
  use, intrinsic :: ieee_arithmetic, only: ieee_is_nan
  use casca_kinds, only: dp
  use casca_deck, only: deck_t, body_cfg_t, obstacle_cfg_t, add_problem, unset, deck_file, max_track
  use casca_files, only: file_kind, kind_missing, kind_regular, physical_memory
  use casca_mesh_generators, only: body_elements, max_generated_elements
  use casca_strings, only: itoa, rtoa, as_word
  use casca_deck_lint, only: did_you_mean
  implicit none
  private
  public :: check_deck, parse_fix, bytes_per_element

  !> Largest size of a number in a deck: far beyond any scene or material, far below the
  !> overflow of the products casca forms (a 1e308 passed every check and overflowed later)
  real(dp), parameter :: max_real = 1e30_dp
  !> Memory a model needs per element, measured with the factors of a sphere of 11,520
  !> elements (36 kB; docs/performance.md has the run), with a margin
  real(dp), parameter :: bytes_per_element = 40e3_dp
  !> Most Newton iterations: newton.f90 keeps the history of at most 100 (its max_hist)
  integer, parameter :: max_newton_iter = 100
  !> Most step halvings: the driver divides dt by the 32-bit integer 2**level
  integer, parameter :: max_cuts = 30
  !> Most steps: the step counter has 32 bits
  real(dp), parameter :: max_steps = 1e9_dp
  !> Most frames: they are named frame_NNNNN.vtu
  real(dp), parameter :: max_frames = 99999

contains

  subroutine check_deck(deck)
    type(deck_t), intent(inout) :: deck
    integer :: i, j, n
    character(len=16) :: ns
    logical :: comps(7), ok

    associate (r => deck%run, l => deck%run%line)
      select case (r%analysis)
      case ('dynamic')
        call positive(l, '&run: dt', r%dt)
        call positive(l, '&run: t_end', r%t_end)
        if (r%dt > 0 .and. r%t_end > 0 .and. r%t_end <= max_real) then
          if (r%dt > r%t_end) call add_problem(deck, l, '&run: dt is larger than t_end')
          if (r%t_end/r%dt > max_steps) call add_problem(deck, l, '&run: t_end/dt = '// &
            rtoa(r%t_end/r%dt)//' steps, more than the 1e9 a run can count')
        end if
        call positive(l, '&run: beta', r%beta)
        call finite(l, '&run: gamma', [r%gamma])
        if (r%gamma < 0.5_dp) call add_problem(deck, l, &
          '&run: gamma must be >= 0.5 (gamma < 1/2 makes Newmark unstable)')
        if (r%rho_inf /= unset .and. .not. (r%rho_inf >= 0 .and. r%rho_inf <= 1)) &
          call add_problem(deck, l, '&run: rho_inf must be in 0..1 (got '//rtoa(r%rho_inf)//')')
        if (r%tolerance /= unset) call positive(l, '&run: tolerance', r%tolerance)
        if (r%tolerance_length /= unset) call positive(l, '&run: tolerance_length', r%tolerance_length)
      case ('static')
        if (r%load_steps < 1) call add_problem(deck, l, '&run: load_steps must be >= 1')
        ! (time-stepping keys a static run would ignore: said, not passed over)
        if (r%tolerance /= unset) call dynamic_only('tolerance')
        if (r%tolerance_length /= unset) call dynamic_only('tolerance_length')
        if (r%rho_inf /= unset .and. r%tolerance == unset) call dynamic_only('rho_inf')   ! (else tolerance's default)
        if (r%linear .and. deck%contact%enabled .and. (size(deck%bodies) > 1 .or. &
            size(deck%obstacles) > 0 .or. deck%contact%npairs > 0)) call add_problem(deck, l, &
          '&run: analysis = ''linear'' has no contact (small displacements, one solve): set '// &
          '&contact enabled = .false. where the bodies stay apart, or use analysis = ''static''')
      case default
        call add_problem(deck, l, '&run: analysis must be ''dynamic'', ''static'' or ''linear'' (got '''// &
                         trim(r%analysis)//''')')
      end select
      if (r%newton_tol /= unset) call positive(l, '&run: newton_tol', r%newton_tol)
      call finite(l, '&run: gravity', r%gravity)
      if (r%newton_max_iter < 1 .or. r%newton_max_iter > max_newton_iter) call add_problem(deck, &
        l, '&run: newton_max_iter must be in 1..'//itoa(max_newton_iter)//' (got '// &
        itoa(r%newton_max_iter)//')')
      if (r%max_step_cuts < 0 .or. r%max_step_cuts > max_cuts) call add_problem(deck, l, &
        '&run: max_step_cuts must be in 0..'//itoa(max_cuts)//' (got '//itoa(r%max_step_cuts)//')')
      if (r%ordering /= 'auto' .and. r%ordering /= 'metis') &
        call add_problem(deck, l, '&run: ordering must be ''auto'' or ''metis''')
      if (r%factor_precision /= 'double' .and. r%factor_precision /= 'single') &
        call add_problem(deck, l, '&run: factor_precision must be ''double'' or ''single'' (got '''// &
                         trim(r%factor_precision)//''')')
    end associate

    associate (o => deck%output, l => deck%output%line)
      if (o%interval /= unset) call positive(l, '&output: interval', o%interval)
      call finite(l, '&output: checkpoint_interval', [o%checkpoint_interval])
      if (o%checkpoint_interval < 0) &
        call add_problem(deck, l, '&output: checkpoint_interval must be >= 0')
      if (o%vtu .and. o%interval > 0 .and. deck%run%t_end > 0 .and. deck%run%dt > 0 .and. &
          deck%run%t_end <= max_real) then
        if (deck%run%t_end/max(o%interval, deck%run%dt) > max_frames) call add_problem(deck, l, &
          '&output: interval gives '//rtoa(deck%run%t_end/max(o%interval, deck%run%dt))// &
          ' frames, more than the 99999 of frame_NNNNN.vtu')
      end if
      if (len_trim(o%dir) == 0) call add_problem(deck, l, '&output: dir is empty')
      call finite(l, '&output: track', reshape(o%track(:, 1:o%ntrack), [3*o%ntrack]))
      if (o%ntrack < max_track) then
        if (any(o%track(:, o%ntrack + 1) /= unset)) &
          call add_problem(deck, l, '&output: track needs 3 coordinates per point')
      end if
      do i = 1, o%ntrack
        if (o%track_body(i) /= '' .and. find_body(o%track_body(i)) == 0) &
          call add_problem(deck, l, '&output: track_body('//itoa(i)//') = '//no_body(o%track_body(i)))
      end do
    end associate

    do i = 1, size(deck%bodies)
      associate (b => deck%bodies(i))
        n = b%line
        if (b%name == '') then
          call add_problem(deck, n, '&body: name is missing')
        else if (count(deck%bodies(:)%name == b%name) > 1) then
          if (find_body(b%name) /= i) &
            call add_problem(deck, n, '&body: name '''//trim(b%name)//''' used twice')
        end if
        call distinct_column(n, '&body', b%name, deck%bodies(1:i - 1)%name)
        call finite(n, '&body '//trim(b%name)//': center', b%center)
        call finite(n, '&body '//trim(b%name)//': rotate_axis', b%rotate_axis)
        call finite(n, '&body '//trim(b%name)//': rotate_angle', [b%rotate_angle])
        call finite(n, '&body '//trim(b%name)//': velocity', b%velocity)
        call finite(n, '&body '//trim(b%name)//': omega', b%omega)
        call finite(n, '&body '//trim(b%name)//': gravity', b%gravity)
        call positive(n, '&body '//trim(b%name)//': young', b%young)
        call positive(n, '&body '//trim(b%name)//': density', b%density)
        call positive(n, '&body '//trim(b%name)//': thickness', b%thickness)
        if (.not. (b%poisson > -1 .and. b%poisson < 0.5_dp)) call add_problem(deck, n, &
          '&body '//trim(b%name)//': poisson must be in (-1, 0.5)')
        if (b%rotate_angle /= 0 .and. .not. norm2(b%rotate_axis) > 0) call add_problem(deck, n, &
          '&body '//trim(b%name)//': rotate_axis must not be zero')
        if (b%element_size /= unset) then
          call positive(n, '&body '//trim(b%name)//': element_size', b%element_size)
          if (b%mesh == 'file') call add_problem(deck, n, '&body '//trim(b%name)// &
            ': element_size sizes the generators (ring, sphere, plate, strip), not a mesh file')
        end if
        select case (b%mesh)
        case ('ring')
          call positive(n, '&body '//trim(b%name)//': radius', b%radius)
          call positive(n, '&body '//trim(b%name)//': width', b%width)
          if (b%n_around < 3 .or. b%n_across < 1) call add_problem(deck, n, '&body '// &
            trim(b%name)//': ring needs n_around >= 3 and n_across >= 1')
        case ('sphere')
          call positive(n, '&body '//trim(b%name)//': radius', b%radius)
          if (b%n_div < 1) call add_problem(deck, n, '&body '//trim(b%name)//': n_div must be >= 1')
        case ('plate', 'strip')
          call positive(n, '&body '//trim(b%name)//': lx', b%lx)
          call positive(n, '&body '//trim(b%name)//': ly', b%ly)
          if (b%nx < 1 .or. b%ny < 1) call add_problem(deck, n, '&body '//trim(b%name)// &
            ': nx and ny must be >= 1')
        case ('file')
          if (b%file == '') then
            call add_problem(deck, n, '&body '//trim(b%name)//': mesh = ''file'' needs file = ...')
          else if (file_kind(deck_file(deck, b%file)) == kind_missing) then
            call add_problem(deck, n, '&body '//trim(b%name)//': mesh file '''// &
                             deck_file(deck, b%file)//''' does not exist')
          else if (file_kind(deck_file(deck, b%file)) /= kind_regular) then
            call add_problem(deck, n, '&body '//trim(b%name)//': mesh file '''// &
                             deck_file(deck, b%file)//''' is not a regular file (a folder, '// &
                             'FIFO or device)')
          end if
        case ('')
          call add_problem(deck, n, '&body '//trim(b%name)// &
                           ': mesh is missing (ring, sphere, plate, strip or file)')
        case default
          call add_problem(deck, n, '&body '//trim(b%name)//': unknown mesh '''//trim(b%mesh)// &
                           ''' (ring, sphere, plate, strip or file)')
        end select
        call check_size(n, b)
      end associate
    end do

    do i = 1, size(deck%restraints)
      associate (r => deck%restraints(i))
        if (r%body /= '' .and. find_body(r%body) == 0) call add_problem(deck, r%line, &
          '&restraint: body = '//no_body(r%body))
        if (size(r%nodes) > 0 .and. r%body == '') call add_problem(deck, r%line, &
          '&restraint: nodes needs body = ... (node numbers count within a body)')
        call check_selection(r%line, '&restraint', r%body, r%set, size(r%nodes), r%box_min, r%box_max)
        call parse_fix(r%fix, comps, ok)
        if (.not. ok) call add_problem(deck, r%line, '&restraint: fix = '''//trim(r%fix)// &
          ''' (use clamped, pinned, all, or components among x y z gx gy gz a)')
        if (any(r%box_min > r%box_max)) call add_problem(deck, r%line, &
          '&restraint: box_min must not exceed box_max')
        if (any(ieee_is_nan([r%box_min, r%box_max]))) call add_problem(deck, r%line, &
          '&restraint: box_min and box_max must be numbers (not NaN)')
      end associate
    end do
    do i = 1, size(deck%loads)
      associate (l => deck%loads(i))
        if (l%body /= '' .and. find_body(l%body) == 0) call add_problem(deck, l%line, &
          '&load: body = '//no_body(l%body))
        if (size(l%nodes) > 0 .and. l%body == '') call add_problem(deck, l%line, &
          '&load: nodes needs body = ... (node numbers count within a body)')
        call check_selection(l%line, '&load', l%body, l%set, size(l%nodes), l%box_min, l%box_max)
        if (l%kind /= 'nodal' .and. l%kind /= 'edge' .and. l%kind /= 'pressure') &
          call add_problem(deck, l%line, '&load: kind = '''//trim(l%kind)// &
                           ''' (use nodal, edge or pressure)')
        if (l%kind == 'pressure' .and. any(l%force /= 0 .or. l%moment /= 0)) call add_problem(deck, &
          l%line, '&load: kind = ''pressure'' takes pressure = ..., not force or moment')
        if (l%kind /= 'pressure' .and. l%pressure /= 0) call add_problem(deck, l%line, &
          '&load: pressure needs kind = ''pressure''')
        call finite(l%line, '&load: pressure', [l%pressure])
        if (any(l%box_min > l%box_max)) call add_problem(deck, l%line, &
          '&load: box_min must not exceed box_max')
        if (any(ieee_is_nan([l%box_min, l%box_max]))) call add_problem(deck, l%line, &
          '&load: box_min and box_max must be numbers (not NaN)')
        call finite(l%line, '&load: force', l%force)
        call finite(l%line, '&load: moment', l%moment)
      end associate
    end do
    call check_memory()
    do j = 1, deck%contact%npairs
      do i = 1, 2
        if (find_body(deck%contact%pairs(i, j)) == 0) then
          write (ns, '(i0)') j
          call add_problem(deck, deck%contact%line, '&contact: pairs(:, '//trim(ns)//') = '// &
                           no_body(deck%contact%pairs(i, j)))
        end if
      end do
    end do
    call positive(deck%contact%line, '&contact: tolerance', deck%contact%tolerance)
    if (deck%contact%stiffness /= unset) &
      call positive(deck%contact%line, '&contact: stiffness', deck%contact%stiffness)
    if (deck%contact%solver /= 'schur' .and. deck%contact%solver /= 'saddle' .and. deck%contact%solver /= 'auto') &
      call add_problem(deck, deck%contact%line, '&contact: solver must be ''auto'', ''schur'' or ''saddle''')
    if (deck%contact%normal /= 'nodal' .and. deck%contact%normal /= 'element') &
      call add_problem(deck, deck%contact%line, '&contact: normal must be ''nodal'' or ''element''')
    if (deck%contact%surface /= 'faces' .and. deck%contact%surface /= 'mid') &
      call add_problem(deck, deck%contact%line, '&contact: surface must be ''faces'' or ''mid''')
    if (deck%contact%passes /= 1 .and. deck%contact%passes /= 2) &
      call add_problem(deck, deck%contact%line, '&contact: passes must be 1 or 2')
    call check_friction(deck%contact%line, '&contact', deck%contact%friction, deck%contact%static_friction)
    call check_decay(deck%contact%line, '&contact: friction_decay', deck%contact%friction_decay)
    do j = 1, size(deck%contact%pair_friction)
      associate (c => deck%contact)
        if (c%pair_friction(j) == unset .and. c%pair_static_friction(j) == unset .and. &
            c%pair_friction_decay(j) == unset) cycle
        if (j > c%npairs) then
          call add_problem(deck, c%line, '&contact: '//pair_key(j)//'('//itoa(j)//') given for pair '// &
                           itoa(j)//', but pairs lists '//itoa(c%npairs))
          cycle
        end if
        call check_friction(c%line, '&contact: pair '//itoa(j), merge(c%pair_friction(j), c%friction, &
                            c%pair_friction(j) /= unset), c%pair_static_friction(j))
        call check_decay(c%line, '&contact: pair_friction_decay('//itoa(j)//')', c%pair_friction_decay(j))
      end associate
    end do
    do i = 1, size(deck%obstacles)
      call check_obstacle(deck%obstacles(i), i)
    end do
  contains
    !> name and an earlier one differ but make the same history column word (casca_strings)
    subroutine distinct_column(line, group, name, earlier)
      integer, intent(in) :: line
      character(len=*), intent(in) :: group, name, earlier(:)
      integer :: j
      do j = 1, size(earlier)
        if (earlier(j) == name .or. as_word(earlier(j)) /= as_word(name)) cycle
        call add_problem(deck, line, group//': name '''//trim(name)//''' and '''//trim(earlier(j))// &
          ''' make the same history column name '''//as_word(name)//''' (every character other '// &
          'than a letter, a digit or _ becomes _); rename one')
        return
      end do
    end subroutine distinct_column

    subroutine check_obstacle(o, io)
      type(obstacle_cfg_t), intent(in) :: o
      integer, intent(in) :: io
      integer :: k
      if (o%name == '') call add_problem(deck, o%line, '&obstacle: name is missing')
      if (find_body(o%name) > 0) call add_problem(deck, o%line, '&obstacle: name = '''// &
        trim(o%name)//''' is also a body''s name')
      if (find_body(o%name) == 0) call distinct_column(o%line, '&obstacle', o%name, &
        [character(len=len(o%name)) :: deck%bodies(:)%name, deck%obstacles(1:io - 1)%name])
      call finite(o%line, '&obstacle: point', o%point)
      call finite(o%line, '&obstacle: velocity', o%velocity)
      select case (o%shape)
      case ('plane')
        call unit_vector(o%line, '&obstacle: normal', o%normal)
        if (o%inside) call add_problem(deck, o%line, '&obstacle: inside is for a sphere or a '// &
          'cylinder (a container); a plane''s side is its normal''s')
      case ('sphere')
        call positive(o%line, '&obstacle: radius', o%radius)
      case ('cylinder')
        call unit_vector(o%line, '&obstacle: axis', o%axis)
        call positive(o%line, '&obstacle: radius', o%radius)
      case default
        call add_problem(deck, o%line, '&obstacle: shape = '''//trim(o%shape)// &
                         ''' (use plane, sphere or cylinder)')
      end select
      if (o%friction /= unset .or. o%static_friction /= unset) call check_friction(o%line, &
        '&obstacle', merge(o%friction, deck%contact%friction, o%friction /= unset), o%static_friction)
      call check_decay(o%line, '&obstacle: friction_decay', o%friction_decay)
      do k = 1, o%nbodies
        if (find_body(o%bodies(k)) == 0) call add_problem(deck, o%line, '&obstacle: bodies = '// &
          no_body(o%bodies(k)))
      end do
    end subroutine check_obstacle

    !> A selection is one of a set (a physical group of its body's mesh), a node list or a box:
    !> given two, one would be dropped without a word
    subroutine check_selection(line, group, body, set, nlist, lo, hi)
      integer, intent(in) :: line, nlist
      character(len=*), intent(in) :: group, body, set
      real(dp), intent(in) :: lo(3), hi(3)
      logical :: box
      box = any(lo /= -huge(1._dp)) .or. any(hi /= huge(1._dp))
      if (set /= '' .and. body == '') call add_problem(deck, line, group//': set needs body = ... (a '// &
                                                       'set is a physical group of a body''s mesh file)')
      if (count([set /= '', nlist > 0, box]) > 1) call add_problem(deck, line, group// &
        ': give one of set, nodes or box_min/box_max (each selects the nodes on its own)')
    end subroutine check_selection

    !> coefficients of friction: >= 0, below 10, the static one (when given) not below the
    !> dynamic one
    subroutine check_friction(line, group, dyn, sta)
      integer, intent(in) :: line
      character(len=*), intent(in) :: group
      real(dp), intent(in) :: dyn, sta
      if (.not. (dyn >= 0 .and. dyn < 10)) call add_problem(deck, line, group// &
        ': friction must be in [0, 10) (got '//rtoa(dyn)//')')
      if (sta == unset) return
      if (.not. (sta >= 0 .and. sta < 10)) then
        call add_problem(deck, line, group//': static_friction must be in [0, 10) (got '//rtoa(sta)//')')
      else if (sta < dyn) then
        call add_problem(deck, line, group//': static_friction ('//rtoa(sta)// &
                         ') must not be below friction ('//rtoa(dyn)//')')
      end if
    end subroutine check_friction

    !> the first of &contact's per-pair friction keys given for pair j
    function pair_key(j) result(key)
      integer, intent(in) :: j
      character(len=:), allocatable :: key
      key = 'pair_friction_decay'
      if (deck%contact%pair_static_friction(j) /= unset) key = 'pair_static_friction'
      if (deck%contact%pair_friction(j) /= unset) key = 'pair_friction'
    end function pair_key

    !> a decay coefficient of the sliding coefficient with slip speed, DC [s/m], when given:
    !> finite and >= 0 (0: the static coefficient at any speed, as LS-DYNA reads it)
    subroutine check_decay(line, field, dc)
      integer, intent(in) :: line
      character(len=*), intent(in) :: field
      real(dp), intent(in) :: dc
      if (dc == unset) return
      if (.not. (dc >= 0 .and. dc < huge(1._dp))) call add_problem(deck, line, field// &
        ' must be >= 0 [s/m], the decay of the sliding coefficient with the slip speed v, '// &
        'mu_d + (mu_s - mu_d) exp(-friction_decay |v|) (got '//rtoa(dc)//')')
    end subroutine check_decay

    subroutine unit_vector(line, field, v)
      integer, intent(in) :: line
      character(len=*), intent(in) :: field
      real(dp), intent(in) :: v(3)
      call finite(line, field, v)
      if (.not. (norm2(v) > 0)) call add_problem(deck, line, field//' must be a non-zero vector')
    end subroutine unit_vector

    !> a key of the time steps in a static deck, which steps its load (load_steps)
    subroutine dynamic_only(key)
      character(len=*), intent(in) :: key
      call add_problem(deck, deck%run%line, '&run: '//key//' is for analysis = ''dynamic''; a static &
        &run steps its load by load_steps (remove '//key//', or set analysis = ''dynamic'')')
    end subroutine dynamic_only

    subroutine positive(line, field, v)
      integer, intent(in) :: line
      character(len=*), intent(in) :: field
      real(dp), intent(in) :: v
      if (v == unset) then
        call add_problem(deck, line, field//' is missing')
      else if (.not. (v > 0)) then
        call add_problem(deck, line, field//' must be > 0 (got '//rtoa(v)//')')
      else if (.not. (v <= max_real)) then
        call add_problem(deck, line, field//' must be > 0 and below 1e30 (got '//rtoa(v)//')')
      end if
    end subroutine positive

    !> v must be finite numbers below max_real in size (NaN fails every comparison)
    subroutine finite(line, field, v)
      integer, intent(in) :: line
      character(len=*), intent(in) :: field
      real(dp), intent(in) :: v(:)
      if (.not. all(abs(v) <= max_real)) call add_problem(deck, line, field// &
        ' must be finite numbers below 1e30 in size (got '//rtoa(v(maxloc(merge(1, 0, &
        .not. abs(v) <= max_real), dim=1)))//')')
    end subroutine finite

    !> a generator's sizes must give at most max_generated_elements
    subroutine check_size(line, b)
      integer, intent(in) :: line
      type(body_cfg_t), intent(in) :: b
      if (body_elements(b) > max_generated_elements) call add_problem(deck, line, '&body '// &
        trim(b%name)//': the sizes give '//rtoa(body_elements(b))// &
        ' elements, more than the 1e7 a generator makes')
    end subroutine check_size

    !> the generated bodies must fit in the machine's memory (before anything is allocated)
    subroutine check_memory()
      real(dp) :: elems(size(deck%bodies))
      integer :: k
      elems = 0
      do k = 1, size(deck%bodies)
        elems(k) = body_elements(deck%bodies(k))
      end do
      if (size(elems) == 0 .or. physical_memory() <= 0) return
      if (sum(elems)*bytes_per_element > real(physical_memory(), dp)) &   ! (at the largest body)
        call add_problem(deck, deck%bodies(maxloc(elems, dim=1))%line, 'the generated meshes '// &
          'have '//rtoa(sum(elems))//' elements in all, needing about '//rtoa(sum(elems)*bytes_per_element/1e9_dp)// &
          ' GB of memory; this machine has '//rtoa(real(physical_memory(), dp)/1e9_dp)//' GB')
    end subroutine check_memory


    !> "'x' is not a body of the deck", with the nearest body name if one is near
    function no_body(name) result(msg)
      character(len=*), intent(in) :: name
      character(len=:), allocatable :: msg
      integer :: k
      msg = ''''//trim(name)//''' is not a body of the deck'
      do k = 1, size(deck%obstacles)   ! (an obstacle's pairs are its own &obstacle bodies)
        if (deck%obstacles(k)%name == name) then
          msg = msg//' but an &obstacle: it meets the bodies its &obstacle bodies lists (every '// &
                'body when not given), not through &contact pairs'
          return
        end if
      end do
      msg = msg//did_you_mean(name, deck%bodies%name)
    end function no_body

    integer function find_body(name)
      character(len=*), intent(in) :: name
      integer :: k
      find_body = 0
      do k = 1, size(deck%bodies)
        if (deck%bodies(k)%name == name) then
          find_body = k; return
        end if
      end do
    end function find_body
  end subroutine check_deck

  !> Components fixed by a restraint: 'clamped' (position and fibre), 'pinned' (position),
  !> 'all', or a list among x y z gx gy gz a.
  subroutine parse_fix(text, comps, ok)
    character(len=*), intent(in) :: text
    logical, intent(out) :: comps(7), ok
    character(len=8), parameter :: names(7) = [character(len=8) :: 'x', 'y', 'z', 'gx', 'gy', 'gz', 'a']
    integer :: i, j, k
    character(len=len(text)) :: w
    comps = .false.; ok = .true.
    select case (trim(adjustl(text)))
    case ('clamped')
      comps(1:6) = .true.; return
    case ('pinned')
      comps(1:3) = .true.; return
    case ('all')
      comps = .true.; return
    end select
    w = text
    i = 1
    do
      do while (i <= len(w))
        if (w(i:i) /= ' ' .and. w(i:i) /= ',') exit
        i = i + 1
      end do
      if (i > len(w)) exit
      j = i
      do while (j <= len(w))
        if (w(j:j) == ' ' .or. w(j:j) == ',') exit
        j = j + 1
      end do
      k = findloc(names, w(i:j - 1), dim=1)
      if (k == 0) then
        ok = .false.; return
      end if
      comps(k) = .true.
      i = j
    end do
    ok = any(comps)
  end subroutine parse_fix
end module casca_sanity
