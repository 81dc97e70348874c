!> A light reading of namelist groups before Fortran's own reader sees them: every key must
!> be one the group knows and every value of the right type. gfortran's messages for these
!> mistakes ("Cannot match namelist object name 'abc'") do not name the field; these do.
module casca_deck_lint
  use casca_strings, only: itoa
  implicit none
  private
  public :: lint_group, outside_text, lower, did_you_mean

  !> Every key of every group and its type: 'r' real, 'i' integer, 'l' logical, 's' string
  !> (the one list: the lint's check and its suggestions read it)
  type :: key_t
    character(len=9) :: group
    character(len=20) :: name
    character(len=1) :: type
  end type key_t
  type(key_t), parameter :: keys(*) = [ &
    key_t('run', 'title', 's'), key_t('run', 'analysis', 's'), key_t('run', 'ordering', 's'), &
    key_t('run', 'factor_precision', 's'), &
    key_t('run', 'dt', 'r'), key_t('run', 't_end', 'r'), key_t('run', 'beta', 'r'), &
    key_t('run', 'gamma', 'r'), key_t('run', 'rho_inf', 'r'), key_t('run', 'newton_tol', 'r'), &
    key_t('run', 'gravity', 'r'), key_t('run', 'tolerance', 'r'), &
    key_t('run', 'tolerance_length', 'r'), &
    key_t('run', 'newton_max_iter', 'i'), key_t('run', 'load_steps', 'i'), &
    key_t('run', 'max_step_cuts', 'i'), key_t('run', 'reuse_factorisation', 'l'), &
    key_t('run', 'skip_idle_bodies', 'l'), key_t('run', 'load_stiffness', 'l'), &
    key_t('output', 'dir', 's'), &
    key_t('output', 'track_body', 's'), key_t('output', 'interval', 'r'), &
    key_t('output', 'checkpoint_interval', 'r'), key_t('output', 'track', 'r'), &
    key_t('output', 'vtu', 'l'), key_t('output', 'plots', 'l'), key_t('body', 'name', 's'), &
    key_t('body', 'mesh', 's'), key_t('body', 'file', 's'), key_t('body', 'radius', 'r'), &
    key_t('body', 'width', 'r'), key_t('body', 'lx', 'r'), key_t('body', 'ly', 'r'), &
    key_t('body', 'center', 'r'), key_t('body', 'rotate_axis', 'r'), &
    key_t('body', 'rotate_angle', 'r'), key_t('body', 'young', 'r'), &
    key_t('body', 'poisson', 'r'), key_t('body', 'density', 'r'), &
    key_t('body', 'thickness', 'r'), key_t('body', 'velocity', 'r'), key_t('body', 'omega', 'r'), &
    key_t('body', 'gravity', 'r'), key_t('body', 'n_around', 'i'), &
    key_t('body', 'n_across', 'i'), key_t('body', 'n_div', 'i'), key_t('body', 'nx', 'i'), &
    key_t('body', 'flip_normals', 'l'), key_t('body', 'element_size', 'r'), &
    key_t('body', 'ny', 'i'), key_t('restraint', 'body', 's'), key_t('restraint', 'fix', 's'), &
    key_t('restraint', 'set', 's'), key_t('restraint', 'box_min', 'r'), &
    key_t('restraint', 'box_max', 'r'), key_t('restraint', 'nodes', 'i'), &
    key_t('load', 'body', 's'), key_t('load', 'set', 's'), key_t('load', 'kind', 's'), &
    key_t('load', 'box_min', 'r'), key_t('load', 'box_max', 'r'), key_t('load', 'force', 'r'), &
    key_t('load', 'nodes', 'i'), key_t('load', 'pressure', 'r'), key_t('load', 'moment', 'r'), &
    key_t('contact', 'pairs', 's'), key_t('contact', 'solver', 's'), &
    key_t('contact', 'normal', 's'), key_t('contact', 'surface', 's'), &
    key_t('contact', 'tolerance', 'r'), key_t('contact', 'friction', 'r'), &
    key_t('contact', 'stiffness', 'r'), &
    key_t('contact', 'static_friction', 'r'), key_t('contact', 'pair_friction', 'r'), &
    key_t('contact', 'pair_static_friction', 'r'), key_t('contact', 'passes', 'i'), &
    key_t('contact', 'friction_decay', 'r'), key_t('contact', 'pair_friction_decay', 'r'), &
    key_t('contact', 'enabled', 'l'), key_t('obstacle', 'name', 's'), &
    key_t('obstacle', 'shape', 's'), key_t('obstacle', 'bodies', 's'), &
    key_t('obstacle', 'point', 'r'), key_t('obstacle', 'normal', 'r'), &
    key_t('obstacle', 'axis', 'r'), key_t('obstacle', 'radius', 'r'), &
    key_t('obstacle', 'velocity', 'r'), key_t('obstacle', 'friction', 'r'), &
    key_t('obstacle', 'static_friction', 'r'), key_t('obstacle', 'friction_decay', 'r'), &
    key_t('obstacle', 'inside', 'l')]

  !> The string keys that take a list (every other string key takes one)
  character(len=10), parameter :: str_lists(*) = [character(len=10) :: 'track_body', 'pairs', 'bodies']

  !> The keys that are vectors of three, in every group they belong to
  character(len=11), parameter :: vec3(*) = [character(len=11) :: 'gravity', 'rotate_axis', &
    'center', 'velocity', 'omega', 'box_min', 'box_max', 'force', 'moment', 'point', 'normal', 'axis']

contains

  !> Type of key in group: 'r' real, 'i' integer, 'l' logical, 's' string, ' ' unknown.
  pure function key_type(group, key) result(t)
    character(len=*), intent(in) :: group, key
    character(len=1) :: t
    integer :: k
    t = ' '
    do k = 1, size(keys)
      if (keys(k)%group == group .and. keys(k)%name == key) then
        t = keys(k)%type; return
      end if
    end do
  end function key_type

  !> Check the group whose '&name' is on line first of text(:). Each problem is returned as
  !> a line number and a message (returned, not reported through a callback: an internal
  !> procedure passed as an argument would need a trampoline on an executable stack); and
  !> each key given (not indexed), with its line. An unknown key is blanked out of text with
  !> its values, so that the namelist read of the rest still checks the other keys' values,
  !> and a key given twice is read as Fortran reads it (the last): one slip does not hide the
  !> deck's other problems (readable: how many of these).
  subroutine lint_group(text, first, group, lines, msgs, keys, key_lines, readable)
    character(len=*), intent(inout) :: text(:)
    character(len=*), intent(in) :: group
    integer, intent(in) :: first
    integer, allocatable, intent(out) :: lines(:)
    character(len=512), allocatable, intent(out) :: msgs(:)
    character(len=20), allocatable, intent(out) :: keys(:)
    integer, allocatable, intent(out) :: key_lines(:)
    integer, intent(out) :: readable
    character(len=:), allocatable :: s, key, item
    integer, allocatable :: lineof(:), colof(:)
    integer :: i, j, k, n, p, bad
    character(len=1) :: t, q
    logical :: done
    integer :: nval, key_line, open_at
    logical :: indexed, comma   !< comma: the last item was a comma

    ! the group as one string (comments cut), with the line of each character
    allocate (lines(0), msgs(0), keys(0), key_lines(0))
    readable = 0; bad = 0   ! (bad: where the unknown key being read starts in s)
    s = ''
    allocate (lineof(0), colof(0))
    do i = first, size(text)
      if (i > first .and. starts_group(text(i))) exit   ! (the next group: this one is open)
      k = comment_start(text(i))
      s = s//text(i)(1:k - 1)//' '
      lineof = [lineof, spread(i, 1, k)]; colof = [colof, (j, j=1, k)]
      if (group_ends(s)) exit
    end do
    if (.not. group_ends(s)) then   ! (the read would run into the next group: keys by the dozen)
      open_at = -group_end(s)   ! (a quote left open takes in the '/' and what follows)
      if (open_at > 0) then
        call report(lineof(open_at), '&'//group//': the quote opened here ('// &
                    trim(adjustl(text(lineof(open_at))(colof(open_at):)))// &
                    ') is not closed, so the group''s ''/'' is inside the string')
      else if (i > size(text)) then
        call report(first, '&'//group//' is not closed with ''/'' before the end of the deck')
      else if (lower(adjustl(text(i))) == '&end') then
        call report(first, '&'//group//' is closed with &end (line '//itoa(i)//'), which casca '// &
                    'does not read: end each group with ''/''')
      else
        call report(first, '&'//group//' is not closed with ''/'' before the next group, at line '// &
                    itoa(i))
      end if
      return
    end if
    n = len(s)
    p = index(s, '&') + 1 + len_trim(group)
    key = ''; t = ' '
    nval = 0; key_line = 0; indexed = .false.; comma = .false.
    done = .false.
    do while (p <= n .and. .not. done)
      select case (s(p:p))
      case (' ', achar(9))
        p = p + 1
      case (',')
        ! (a null value: Fortran's read says only "Cannot match namelist object name")
        if (comma .and. key /= '' .and. t /= ' ') then
          call report(lineof(p), '&'//group//': '//key//' has an empty value (two commas with '// &
                      'nothing between)')
          comma = .false.   ! (once for a run of commas)
        else
          comma = .true.
        end if
        p = p + 1
      case ('/')
        call key_done()
        call blank_bad()
        done = .true.
      case ("'", '"')
        comma = .false.
        q = s(p:p)
        j = p + 1   ! (the closing quote: a doubled one, 'it''s', is a quote inside)
        do
          k = index(s(j:), q)
          if (k == 0) then
            j = n; exit
          end if
          j = j + k - 1
          if (j < n) then
            if (s(j + 1:j + 1) == q) then
              j = j + 2; cycle
            end if
          end if
          exit
        end do
        call value(s(p:j), lineof(p))
        p = j + 1
      case default
        comma = .false.
        j = p
        do while (j <= n)
          if (index(' ,/=', s(j:j)) > 0 .or. s(j:j) == achar(9)) exit
          j = j + 1
        end do
        item = s(p:j - 1)
        k = j
        do while (k <= n)
          if (s(k:k) /= ' ') exit
          k = k + 1
        end do
        if (k <= n .and. s(k:k) == '=') then   ! a key
          call key_done()
          call blank_bad()
          key = lower(item)
          indexed = index(key, '(') > 0
          if (indexed) key = key(1:index(key, '(') - 1)
          t = key_type(group, key)
          if (t == ' ') then
            call report(lineof(p), '&'//group//': unknown key '''//key//''''//suggestion(group, key))
            bad = p; readable = readable + 1
          end if
          key_line = lineof(p); nval = 0
          if (t /= ' ' .and. .not. indexed) call once()
          p = k + 1
        else
          call value(item, lineof(p))
          p = j
        end if
      end select
    end do
  contains
    subroutine value(v, line)
      character(len=*), intent(in) :: v
      integer, intent(in) :: line
      character(len=:), allocatable :: w
      integer :: ios, iv, star
      real :: rv
      logical :: lv
      if (key == '' .or. t == ' ') return
      w = v
      nval = nval + 1
      star = index(w, '*')   ! repeat count r*value
      if (star > 0 .and. verify(w(1:max(star - 1, 1)), '0123456789') == 0) then
        read (w(1:star - 1), *, iostat=ios) iv
        if (ios == 0) nval = nval - 1 + iv
        w = w(star + 1:)
      end if
      if (len(w) == 0) return
      ios = 0
      select case (t)
      case ('s')
        if (w(1:1) /= "'" .and. w(1:1) /= '"') ios = 1
      case ('r')
        if (w(1:1) == "'" .or. w(1:1) == '"' .or. w(1:1) == '.') then
          if (verify(w(1:1), '.') == 0 .and. verify(w(2:2), '0123456789') == 0 .and. len(w) > 1) then
            read (w, *, iostat=ios) rv
          else
            ios = 1
          end if
        else
          read (w, *, iostat=ios) rv
        end if
      case ('i')
        if (verify(w, '+-0123456789') /= 0) ios = 1
        if (ios == 0) read (w, *, iostat=ios) iv
      case ('l')
        select case (lower(w))
        case ('.true.', '.false.', 't', 'f', '.t.', '.f.')
          lv = .true.
        case default
          ios = 1
        end select
      end select
      if (ios /= 0) call report(line, '&'//group//': '//key//' = '//w//' is not '//kind_name(t))
    end subroutine value

    !> A key given twice in a group: Fortran's read keeps the last silently (a deck with two
    !> thickness lines ran with the second)
    subroutine once()
      integer :: m
      do m = 1, size(keys)
        if (keys(m) /= key) cycle
        if (key_lines(m) == key_line) then
          call report(key_line, '&'//group//': '//key//' is given twice on this line: keep one')
        else
          call report(key_line, '&'//group//': '//key//' is given twice (lines '//itoa(key_lines(m))// &
                      ' and '//itoa(key_line)//'): keep one')
        end if
        readable = readable + 1
        return
      end do
      keys = [character(len=20) :: keys, key]
      key_lines = [key_lines, key_line]
    end subroutine once

    !> The key just read is complete: a vector of three takes three numbers (the read fills
    !> what is missing from the default and drops nothing: velocity = 1.0, 2.0 ran with vz 0);
    !> a string key takes one string unless it is a list (fix = 'x','y','z' met gfortran's
    !> "Cannot match namelist object name 'y''z'", or "End of file" in the deck's last group)
    subroutine key_done()
      if (key == '' .or. indexed) return
      if (t == 's' .and. nval > 1 .and. all(key /= str_lists)) then
        if (key == 'fix') then
          call report(key_line, '&'//group//': fix takes one string, '//itoa(nval)// &
                      " given: its components in one, fix = 'x y z'")
        else
          call report(key_line, '&'//group//': '//key//' takes one string, '//itoa(nval)//' given')
        end if
        return
      end if
      if (t /= 'r') return
      if (all(key /= vec3)) return
      if (nval /= 3) call report(key_line, '&'//group//': '//key//' takes 3 numbers (x, y, z), '// &
                                 itoa(nval)//' given')
    end subroutine key_done

    !> the unknown key read last and its values, up to where the next key or the '/' is (p)
    subroutine blank_bad()
      integer :: m
      if (bad == 0) return
      do m = bad, p - 1
        text(lineof(m))(colof(m):colof(m)) = ' '
      end do
      bad = 0
    end subroutine blank_bad

    subroutine report(line, msg)
      integer, intent(in) :: line
      character(len=*), intent(in) :: msg
      lines = [lines, line]
      msgs = [character(len=512) :: msgs, msg]
    end subroutine report
  end subroutine lint_group

  !> The text outside every group: a group's name written without its '&', stray words
  !> between groups, words after a group's '/' on its line. The namelist read skips them
  !> without a word (a restraint written 'restraint' vanished from a run); blanks and '!'
  !> comments may stand there. Told once until the next group; a group left open is the
  !> lint's to report (its text is skipped here).
  subroutine outside_text(text, lines, msgs)
    character(len=*), intent(in) :: text(:)
    integer, allocatable, intent(out) :: lines(:)
    character(len=512), allocatable, intent(out) :: msgs(:)
    character(len=:), allocatable :: s, line
    integer :: i, at, start
    logical :: inside, after, told   !< after: in a group on this line, before its '/'
    allocate (lines(0), msgs(0))
    inside = .false.; told = .false.; s = ''
    do i = 1, size(text)
      line = text(i)(1:comment_start(text(i)) - 1)
      if (starts_group(line)) then
        inside = .true.; told = .false.; s = ''
      end if
      after = inside
      if (inside) then   ! (its '/' is on this line if the text so far holds it, quotes aside)
        start = len(s)
        s = s//line//' '
        at = group_end(s)
        if (at <= 0) cycle
        inside = .false.
        line = line(at - start + 1:)
      end if
      if (told .or. verify(line, ' '//achar(9)) == 0) cycle
      line = trim(adjustl(line))
      if (len(line) > 60) line = line(1:57)//'...'
      lines = [lines, i]; told = .true.
      if (after) then
        msgs = [character(len=512) :: msgs, 'text after the group''s closing ''/'': '''//line// &
                ''' (a group ends at its ''/'')']
      else
        msgs = [character(len=512) :: msgs, 'text outside a group: '''//line// &
                ''' (a group starts with &)']
      end if
    end do
  end subroutine outside_text

  pure function kind_name(t) result(s)
    character(len=1), intent(in) :: t
    character(len=:), allocatable :: s
    select case (t)
    case ('r'); s = 'a number'
    case ('i'); s = 'an integer'
    case ('l'); s = 'a logical (.true. or .false.)'
    case default; s = 'a quoted string'
    end select
  end function kind_name

  !> where a '!' comment starts outside quotes (len+1 if none)
  pure integer function comment_start(line)
    character(len=*), intent(in) :: line
    character(len=1) :: q
    integer :: i
    q = ' '
    comment_start = len_trim(line) + 1
    do i = 1, len_trim(line)
      if (q /= ' ') then
        if (line(i:i) == q) q = ' '
      else if (line(i:i) == "'" .or. line(i:i) == '"') then
        q = line(i:i)
      else if (line(i:i) == '!') then
        comment_start = i; return
      end if
    end do
  end function comment_start

  !> a line whose first character that is not a blank is '&'
  pure logical function starts_group(line)
    character(len=*), intent(in) :: line
    integer :: i
    i = verify(line, ' '//achar(9))
    starts_group = .false.
    if (i > 0) starts_group = line(i:i) == '&'
  end function starts_group

  !> the text holds a '/' outside quotes (end of the group)
  pure logical function group_ends(s)
    character(len=*), intent(in) :: s
    group_ends = group_end(s) > 0
  end function group_ends

  !> Where in s (a group's text) its '/' is, outside quotes; 0 if none, and then -k if a
  !> quote opened at k is still open at the end (a '/' after it is inside the string)
  pure integer function group_end(s) result(at)
    character(len=*), intent(in) :: s
    character(len=1) :: q
    integer :: i, opened
    logical :: doubled
    q = ' '; opened = 0; doubled = .false.
    do i = 1, len(s)
      if (doubled) then   ! (the second of a doubled quote, 'it''s': a quote inside)
        doubled = .false.
      else if (q /= ' ') then
        if (s(i:i) == q) then
          q = ' '
          if (i < len(s)) then
            if (s(i + 1:i + 1) == s(i:i)) then
              q = s(i:i); doubled = .true.
            end if
          end if
        end if
      else if (s(i:i) == "'" .or. s(i:i) == '"') then
        q = s(i:i); opened = i
      else if (s(i:i) == '/') then
        at = i; return
      end if
    end do
    at = 0
    if (q /= ' ') at = -opened
  end function group_end

  !> ' (did you mean ''x''?)' for the nearest key of the group; a key of other groups named
  !> as theirs (a body's pressure was met with "did you mean 'pressure'?"); else the nearest
  !> key of any group
  function suggestion(group, key) result(s)
    character(len=*), intent(in) :: group, key
    character(len=:), allocatable :: s
    integer :: k
    s = did_you_mean(key, pack(keys%name, keys%group == group))
    if (s /= '') return
    do k = 1, size(keys)
      if (keys(k)%name /= key) cycle
      if (s == '') then
        s = ' (a key of &'//trim(keys(k)%group)
      else
        s = s//' and &'//trim(keys(k)%group)
      end if
    end do
    if (s /= '') then
      s = s//')'
    else
      s = did_you_mean(key, keys%name)
    end if
  end function suggestion

  !> ' (did you mean ''x''?)' for the candidate nearest to name by edit distance (at most 2
  !> edits), else ''
  function did_you_mean(name, candidates) result(s)
    character(len=*), intent(in) :: name, candidates(:)
    character(len=:), allocatable :: s
    integer :: i, d, best
    s = ''
    best = 3
    do i = 1, size(candidates)
      d = edit_distance(trim(name), trim(candidates(i)))
      if (d < best) then
        best = d; s = ' (did you mean '''//trim(candidates(i))//'''?)'
      end if
    end do
  end function did_you_mean

  pure integer function edit_distance(a, b) result(d)
    character(len=*), intent(in) :: a, b
    integer :: row(0:len(b)), prev, tmp, i, j
    row = [(j, j=0, len(b))]
    do i = 1, len(a)
      prev = row(0); row(0) = i
      do j = 1, len(b)
        tmp = row(j)
        row(j) = min(row(j) + 1, row(j - 1) + 1, prev + merge(0, 1, a(i:i) == b(j:j)))
        prev = tmp
      end do
    end do
    d = row(len(b))
  end function edit_distance

  pure function lower(s) result(t)
    character(len=*), intent(in) :: s
    character(len=len(s)) :: t
    integer :: i
    t = s
    do i = 1, len(s)
      if (s(i:i) >= 'A' .and. s(i:i) <= 'Z') t(i:i) = achar(iachar(s(i:i)) + 32)
    end do
  end function lower
end module casca_deck_lint
