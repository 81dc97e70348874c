!> Checks of a deck's values before any work (CaNS's sanity module): every problem is added
!> to deck%problems with the deck's file name, the group's line and the field.
module casca_sanity
  use casca_kinds, only: dp
  use casca_deck, only: deck_t, add_problem, unset, deck_file
  implicit none
  private
  public :: check_deck, parse_fix

contains

  subroutine check_deck(deck)
    type(deck_t), intent(inout) :: deck
    integer :: i, j, n
    logical :: exists
    character(len=16) :: ns
    logical :: comps(7), ok

    associate (r => deck%run)
      select case (r%analysis)
      case ('dynamic')
        call positive(0, '&run: dt', r%dt)
        call positive(0, '&run: t_end', r%t_end)
        if (r%dt /= unset .and. r%t_end /= unset .and. r%dt > 0) then
          if (r%dt > r%t_end) call add_problem(deck, 0, '&run: dt is larger than t_end')
        end if
        call positive(0, '&run: beta', r%beta)
        if (r%gamma < 0.5_dp) call add_problem(deck, 0, &
          '&run: gamma must be >= 0.5 (gamma < 1/2 makes Newmark unstable)')
      case ('static')
        if (r%load_steps < 1) call add_problem(deck, 0, '&run: load_steps must be >= 1')
      case default
        call add_problem(deck, 0, '&run: analysis must be ''dynamic'' or ''static'' (got '''// &
                         trim(r%analysis)//''')')
      end select
      call positive(0, '&run: newton_tol', r%newton_tol)
      if (r%newton_max_iter < 1) call add_problem(deck, 0, '&run: newton_max_iter must be >= 1')
      if (r%max_step_cuts < 0) call add_problem(deck, 0, '&run: max_step_cuts must be >= 0')
      if (r%ordering /= 'auto' .and. r%ordering /= 'metis') &
        call add_problem(deck, 0, '&run: ordering must be ''auto'' or ''metis''')
    end associate

    associate (o => deck%output)
      if (o%interval /= unset .and. .not. (o%interval > 0)) &
        call add_problem(deck, 0, '&output: interval must be > 0')
      if (o%checkpoint_interval < 0) &
        call add_problem(deck, 0, '&output: checkpoint_interval must be >= 0')
      if (len_trim(o%dir) == 0) call add_problem(deck, 0, '&output: dir is empty')
      do i = 1, o%ntrack
        if (o%track_body(i) /= '' .and. find_body(o%track_body(i)) == 0) &
          call add_problem(deck, 0, '&output: track_body('//itoa(i)//') = '''// &
                           trim(o%track_body(i))//''' is not a body of the deck')
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
        call positive(n, '&body '//trim(b%name)//': young', b%young)
        call positive(n, '&body '//trim(b%name)//': density', b%density)
        call positive(n, '&body '//trim(b%name)//': thickness', b%thickness)
        if (.not. (b%poisson > -1 .and. b%poisson < 0.5_dp)) call add_problem(deck, n, &
          '&body '//trim(b%name)//': poisson must be in (-1, 0.5)')
        if (b%rotate_angle /= 0 .and. .not. norm2(b%rotate_axis) > 0) call add_problem(deck, n, &
          '&body '//trim(b%name)//': rotate_axis must not be zero')
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
          inquire (file=deck_file(deck, b%file), exist=exists)
          if (b%file == '') then
            call add_problem(deck, n, '&body '//trim(b%name)//': mesh = ''file'' needs file = ...')
          else if (.not. exists) then
            call add_problem(deck, n, '&body '//trim(b%name)//': mesh file '''// &
                             deck_file(deck, b%file)//''' does not exist')
          end if
        case ('')
          call add_problem(deck, n, '&body '//trim(b%name)// &
                           ': mesh is missing (ring, sphere, plate, strip or file)')
        case default
          call add_problem(deck, n, '&body '//trim(b%name)//': unknown mesh '''//trim(b%mesh)// &
                           ''' (ring, sphere, plate, strip or file)')
        end select
      end associate
    end do

    do i = 1, size(deck%restraints)
      associate (r => deck%restraints(i))
        if (r%body /= '' .and. find_body(r%body) == 0) call add_problem(deck, r%line, &
          '&restraint: body = '''//trim(r%body)//''' is not a body of the deck')
        if (size(r%nodes) > 0 .and. r%body == '') call add_problem(deck, r%line, &
          '&restraint: nodes needs body = ... (node numbers count within a body)')
        call parse_fix(r%fix, comps, ok)
        if (.not. ok) call add_problem(deck, r%line, '&restraint: fix = '''//trim(r%fix)// &
          ''' (use clamped, pinned, all, or components among x y z gx gy gz a)')
        if (any(r%box_min > r%box_max)) call add_problem(deck, r%line, &
          '&restraint: box_min must not exceed box_max')
      end associate
    end do
    do i = 1, size(deck%loads)
      associate (l => deck%loads(i))
        if (l%body /= '' .and. find_body(l%body) == 0) call add_problem(deck, l%line, &
          '&load: body = '''//trim(l%body)//''' is not a body of the deck')
        if (size(l%nodes) > 0 .and. l%body == '') call add_problem(deck, l%line, &
          '&load: nodes needs body = ... (node numbers count within a body)')
        if (any(l%box_min > l%box_max)) call add_problem(deck, l%line, &
          '&load: box_min must not exceed box_max')
      end associate
    end do
    do j = 1, deck%contact%npairs
      do i = 1, 2
        if (find_body(deck%contact%pairs(i, j)) == 0) then
          write (ns, '(i0)') j
          call add_problem(deck, deck%contact%line, '&contact: pairs(:, '//trim(ns)//') names '''// &
                           trim(deck%contact%pairs(i, j))//''', which is not a body of the deck')
        end if
      end do
    end do
    call positive(deck%contact%line, '&contact: tolerance', deck%contact%tolerance)
    if (deck%contact%solver /= 'schur' .and. deck%contact%solver /= 'saddle') &
      call add_problem(deck, deck%contact%line, '&contact: solver must be ''schur'' or ''saddle''')
    if (deck%contact%normal /= 'nodal' .and. deck%contact%normal /= 'element') &
      call add_problem(deck, deck%contact%line, '&contact: normal must be ''nodal'' or ''element''')
  contains
    subroutine positive(line, field, v)
      integer, intent(in) :: line
      character(len=*), intent(in) :: field
      real(dp), intent(in) :: v
      character(len=32) :: s
      if (v == unset) then
        call add_problem(deck, line, field//' is missing')
      else if (.not. (v > 0)) then
        write (s, '(es12.4)') v
        call add_problem(deck, line, field//' must be > 0 (got '//trim(adjustl(s))//')')
      end if
    end subroutine positive

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

    function itoa(k) result(s)
      integer, intent(in) :: k
      character(len=:), allocatable :: s
      character(len=16) :: b
      write (b, '(i0)') k
      s = trim(b)
    end function itoa
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
