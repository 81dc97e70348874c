!> Time-history plots of a run, drawn by gnuplot from DIR/history.dat.
!>
!> make_plots reads the header of history.dat (to learn the column numbers and the number K of
!> tracked nodes) and checks that every row below it holds a number for each of its names
!> (gnuplot would skip a bad field, or read a number cut short as another), writes DIR/plots.gp
!> and runs it with gnuplot inside DIR (gnuplot's
!> messages go to DIR/gnuplot.log). The script names files relative to DIR and keeps the column
!> numbers in variables at its top, so a user can edit it and re-run `gnuplot plots.gp` in the
!> run folder without casca. Columns are looked up by name (not position), so extra columns
!> added to history.dat later do not break the plots.
!>
!> Units are SI as the solver writes them (s, m, J, N); time is plotted in ms, and a static
!> run's first column, its load factor, as it is.
module casca_plots
  use casca_kinds, only: dp
  use casca_error, only: error_t, fatal_error
  use casca_strings, only: itoa
  use casca_files, only: ends_in_newline
  implicit none
  private
  public :: make_plots, plot_files

  character(len=*), parameter :: nl = achar(10)
  !> Every file make_plots writes into DIR (its script's 'set output' names): a new run into
  !> the folder removes them, as they are the earlier run's
  character(len=*), parameter :: plot_files(10) = [character(len=17) :: 'plots.gp', 'gnuplot.log', &
    'positions_x.png', 'positions_y.png', 'positions_z.png', 'displacements.png', 'energy.png', &
    'momentum.png', 'contact.png', 'newton.png']
  integer, parameter :: msg_len = 512
  !> UTF-8 middle dot and superscript two for units (kept out of the source as raw bytes).
  character(len=*), parameter :: mdot = char(194)//char(183), sup2 = char(194)//char(178)

  !> One whitespace-separated token of a line.
  type :: word_t
    character(len=:), allocatable :: s
  end type word_t

  !> Columns every history.dat has (see the solver's history writer).
  integer, parameter :: nreq = 15
  character(len=*), parameter :: req_names(nreq) = [character(len=8) :: &
    't', 'step', 'kinetic', 'strain', 'work', 'total', 'px', 'py', 'pz', &
    'Lx', 'Ly', 'Lz', 'contacts', 'fcontact', 'newton']
  !> Per tracked node k: pk_x pk_y pk_z pk_vx pk_vy pk_vz.
  character(len=*), parameter :: node_suffix(6) = [character(len=3) :: 'x', 'y', 'z', 'vx', 'vy', 'vz']

contains

  !> Write DIR/plots.gp from the header of DIR/history.dat and run gnuplot on it in DIR.
  !> If gnuplot is not installed this is not an error: gnuplot_missing (if present) is set
  !> .true. and the script is left for the user. A failing gnuplot run is an error.
  !> A last line cut mid-row (a run killed while writing it, a truncated copy) is left out of
  !> the plots, and note (if present) says so; a bad row anywhere else is an error.
  subroutine make_plots(dir, err, gnuplot_missing, static, note)
    character(len=*), intent(in) :: dir
    type(error_t), allocatable, intent(out) :: err
    logical, intent(out), optional :: gnuplot_missing
    !> a static run (first column: the load factor); not given, one whose kinetic energy is
    !> 0 in every row (casca plot DIR, which has the history alone)
    logical, intent(in), optional :: static
    !> what was left out of the plots, unallocated if nothing
    character(len=:), allocatable, intent(out), optional :: note

    character(len=:), allocatable :: d, hist, script, cmd
    type(word_t), allocatable :: labels(:), names(:)
    integer :: col(nreq), nk, stat, cstat, rows, cut
    integer, allocatable :: pcol(:, :)
    character(len=msg_len) :: cmsg
    logical :: by_load, still

    if (present(gnuplot_missing)) gnuplot_missing = .false.
    d = clean_dir(dir)
    hist = d//'/history.dat'

    call read_header(hist, names, col, pcol, err)
    if (allocated(err)) return
    call check_rows(hist, names, col(findloc(req_names, 'kinetic', dim=1)), rows, cut, still, err)
    if (allocated(err)) return
    if (cut > 0 .and. present(note)) note = hist//': line '//itoa(cut)//' is cut short (a run '// &
      'killed while writing it, or a truncated copy) and was left out; plotted the '// &
      itoa(rows)//' whole rows before it'
    nk = size(pcol, 2)
    call read_labels(d//'/tracked.txt', nk, labels)

    if (present(static)) then
      by_load = static
    else
      by_load = still
    end if
    script = gnuplot_script(col, pcol, labels, by_load, rows, cut)
    call write_text(d//'/plots.gp', script, err)
    if (allocated(err)) return

    ! The one shell of casca: `command -v` is the portable way to ask whether gnuplot is on
    ! PATH (dash answers 127 for "not found", which gfortran reports as a cmdstat failure,
    ! hence exit 99); the folder is one quoted word. gnuplot's messages go to gnuplot.log in
    ! the folder, not the terminal: its warnings (an empty y range where a curve is flat, as
    ! the energies of a static run) are not casca's, and a failure names the log.
    if (d(1:1) /= '/') d = './'//d   ! a folder named -x is not an option of cd
    cmd = 'cd '//shell_quote(d)//' && { command -v gnuplot >/dev/null 2>&1 || exit 99; } && ' &
          //'gnuplot plots.gp 2>gnuplot.log'
    cmsg = ''
    call execute_command_line(cmd, exitstat=stat, cmdstat=cstat, cmdmsg=cmsg)
    if (cstat /= 0) then
      call fatal_error(err, 'make_plots: could not run `'//cmd//'`: '//trim(cmsg))
    else if (stat == 99) then
      if (present(gnuplot_missing)) gnuplot_missing = .true.
    else if (stat /= 0) then
      call fatal_error(err, 'make_plots: `'//cmd//'` failed with exit status '//itoa(stat)// &
                       '; gnuplot''s messages are in '//d//'/gnuplot.log')
    end if
  end subroutine make_plots

  !> Read the '#' header of path into its column names, the column numbers of the required
  !> columns (col) and of the tracked-node columns pcol(1:6, 1:K).
  subroutine read_header(path, names, col, pcol, err)
    character(len=*), intent(in) :: path
    type(word_t), allocatable, intent(out) :: names(:)
    integer, intent(out) :: col(nreq)
    integer, allocatable, intent(out) :: pcol(:, :)
    type(error_t), allocatable, intent(out) :: err

    character(len=:), allocatable :: line, head
    character(len=msg_len) :: msg
    integer :: u, ios, i, j, k, nk, p

    allocate (pcol(6, 0))
    col = 0
    open (newunit=u, file=path, status='old', action='read', form='formatted', iostat=ios, iomsg=msg)
    if (ios /= 0) then
      call fatal_error(err, 'make_plots: cannot open '//path//': '//trim(msg))
      return
    end if

    call read_line(u, line, ios)
    if (ios /= 0) then
      close (u)
      call fatal_error(err, 'make_plots: '//path//' is empty (expected a "# t step ..." header)')
      return
    end if
    head = adjustl(line)
    if (len_trim(head) == 0) then
      p = 0
    else
      p = index(head, '#')
    end if
    if (p /= 1) then
      close (u)
      call fatal_error(err, 'make_plots: '//path//': line 1 is not a "# t step ..." header')
      return
    end if
    names = split(head(2:))

    do i = 1, nreq
      col(i) = find(names, trim(req_names(i)))
      if (col(i) == 0) then
        close (u)
        call fatal_error(err, 'make_plots: '//path//': header has no column "' &
                         //trim(req_names(i))//'"')
        return
      end if
    end do

    ! Tracked nodes are numbered 1..K without gaps; all six columns of each must be present.
    nk = 0
    do while (find(names, 'p'//itoa(nk + 1)//'_x') > 0)
      nk = nk + 1
    end do
    deallocate (pcol)
    allocate (pcol(6, nk))
    do k = 1, nk
      do j = 1, 6
        pcol(j, k) = find(names, 'p'//itoa(k)//'_'//trim(node_suffix(j)))
        if (pcol(j, k) == 0) then
          close (u)
          call fatal_error(err, 'make_plots: '//path//': header has no column "p'//itoa(k) &
                           //'_'//trim(node_suffix(j))//'"')
          return
        end if
      end do
    end do

    close (u)
  end subroutine read_header

  !> Check the rows below the header of path (the lines not starting with '#', as gnuplot
  !> reads them): each a number for each of the header's names. rows: how many there are
  !> before cut, the line number of a last line cut short (0 if none): a line the writer
  !> finished ends with a newline, and one without it may hold a number cut to another
  !> (1.25e+03 cut to 1.25e+0), so it is left out whatever it holds. still: column kin (the
  !> kinetic energy) is 0 in every one of those rows (read in the same pass).
  subroutine check_rows(path, names, kin, rows, cut, still, err)
    character(len=*), intent(in) :: path
    type(word_t), intent(in) :: names(:)
    integer, intent(in) :: kin
    integer, intent(out) :: rows, cut
    logical, intent(out) :: still
    type(error_t), allocatable, intent(out) :: err

    character(len=:), allocatable :: line, what
    type(word_t), allocatable :: w(:)
    real(dp) :: x
    integer :: u, ios, n, last, bad, moving
    logical :: open_end

    rows = 0; cut = 0; last = 0; moving = 0; still = .false.
    open_end = .not. ends_in_newline(path)
    open (newunit=u, file=path, status='old', action='read', form='formatted', iostat=ios)
    if (ios /= 0) then
      call fatal_error(err, 'make_plots: cannot open '//path); return
    end if
    call read_line(u, line, ios)   ! (the header)
    n = 1
    do
      call read_line(u, line, ios)
      if (ios /= 0) exit
      n = n + 1
      if (index(adjustl(line), '#') == 1) cycle
      w = split(line)
      bad = not_a_number(w)
      if (size(w) /= size(names)) then
        what = ': '//itoa(size(w))//' fields where the header names '//itoa(size(names))
      else if (bad > 0) then
        what = ', column '//itoa(bad)//' ('//names(bad)%s//'): "'//w(bad)%s//'" is not a number'
      else
        rows = rows + 1; last = n
        read (w(kin)%s, *) x
        if (x /= 0 .and. moving == 0) moving = n
        cycle
      end if
      call read_line(u, line, ios)
      if (.not. (open_end .and. ios /= 0)) then   ! not a last line cut short
        close (u)
        call fatal_error(err, 'make_plots: '//path//': line '//itoa(n)//what)
        return
      end if
      cut = n
      exit
    end do
    close (u)
    if (open_end .and. last == n) then   ! a whole row's fields, but cut short all the same
      cut = n; rows = rows - 1
    end if
    still = moving == 0 .or. moving == cut
    if (rows == 0) then
      what = ''
      if (cut > 0) what = ' (line '//itoa(cut)//', cut short, is left out)'
      call fatal_error(err, 'make_plots: '//path//' has a header but no data rows'//what)
    end if
  end subroutine check_rows

  !> Index of the first of the words w that is not a number, 0 if none
  integer function not_a_number(w) result(k)
    type(word_t), intent(in) :: w(:)
    real(dp) :: x
    integer :: ios
    do k = 1, size(w)
      read (w(k)%s, *, iostat=ios) x
      if (ios /= 0) return
    end do
    k = 0
  end function not_a_number

  !> Labels of the tracked nodes: line k of path (tracked.txt), or "node k" if the file or
  !> the line is missing or blank.
  subroutine read_labels(path, nk, labels)
    character(len=*), intent(in) :: path
    integer, intent(in) :: nk
    type(word_t), allocatable, intent(out) :: labels(:)

    character(len=:), allocatable :: line
    integer :: u, ios, k
    logical :: exists

    allocate (labels(nk))
    do k = 1, nk
      labels(k)%s = 'node '//itoa(k)
    end do
    inquire (file=path, exist=exists)
    if (exists) then
      open (newunit=u, file=path, status='old', action='read', form='formatted', iostat=ios)
      if (ios == 0) then
        do k = 1, nk
          call read_line(u, line, ios)
          if (ios /= 0) exit
          line = trim(adjustl(untab(line)))
          if (len(line) > 0) labels(k)%s = line
        end do
        close (u)
      end if
    end if
  end subroutine read_labels

  !> The gnuplot script. Column numbers go in variables at the top so the plot commands read
  !> by name; the terminal falls back to libgd `png` where cairo is not built in.
  function gnuplot_script(col, pcol, labels, by_load, rows, cut) result(s)
    integer, intent(in) :: col(nreq), pcol(:, :)
    type(word_t), intent(in) :: labels(:)
    logical, intent(in) :: by_load   !< a static run: against the load factor
    integer, intent(in) :: rows, cut   !< the whole rows, and the line cut short after them (0: none)
    character(len=:), allocatable :: s
    character(len=:), allocatable :: x_of, x_label, versus

    character(len=*), parameter :: axis(3) = ['x', 'y', 'z']
    character(len=:), allocatable :: v
    integer :: i, k, a, nk

    nk = size(pcol, 2)
    if (by_load) then
      x_of = 'ms(c) = column(c)   # a static run: the load factor as it is'
      x_label = 'load factor [-]'; versus = ' vs load factor'
    else
      x_of = 'ms(c) = column(c)*1.0e3   # s -> ms'
      x_label = 'time [ms]'; versus = ' vs time'
    end if
    s = '# Time-history plots of a casca run, written by casca from the header of history.dat.' &
        //nl//'# Edit freely and re-run inside the run folder with:  gnuplot plots.gp'//nl// &
        '# history.dat is in SI units (s, m, J, N); time is plotted in ms.'//nl//nl// &
        "datafile = 'history.dat'"//nl
    ! (a macro, as gnuplot's every takes no variable for 'to the end'; every counts the rows
    ! from 0, the header and '#' lines left out)
    if (cut > 0) then
      s = s//'# line '//itoa(cut)//' of history.dat was cut short (a run killed while writing '// &
          'it, or a truncated copy): only the '//itoa(rows)//' whole rows before it are plotted'// &
          nl//"rows = 'every ::0::"//itoa(rows - 1)//"'"//nl
    else
      s = s//"rows = ''   # every row; 'every ::0::N' plots rows 0 to N only"//nl
    end if
    s = s//nl//'# Column numbers in history.dat'//nl
    do i = 1, nreq
      s = s//'c_'//trim(req_names(i))//' = '//itoa(col(i))//nl
    end do
    do k = 1, nk
      s = s//'# tracked node '//itoa(k)//': '//comment_safe(labels(k)%s)//nl
      do a = 1, 6
        s = s//'c_p'//itoa(k)//'_'//trim(node_suffix(a))//' = '//itoa(pcol(a, k))//nl
      end do
    end do

    s = s//nl// &
        x_of//nl// &
        'imax(a, b) = (a > b) ? a : b'//nl//nl// &
        '# Terminal: cairo if available (antialiased), else libgd. Text is not "enhanced", so'//nl// &
        '# labels with _ or ^ print literally; units use UTF-8 characters instead.'//nl// &
        'set encoding utf8'//nl// &
        "if (strstrt(GPVAL_TERMINALS, 'pngcairo') > 0) {"//nl// &
        '  term = "pngcairo noenhanced font ''Sans,12''"'//nl// &
        '} else {'//nl// &
        "  term = 'png noenhanced'"//nl// &
        '}'//nl// &
        'set terminal @term size 1000,600'//nl//nl// &
        'set style line 100 lc rgb "#c8c8c8" lw 1 dt 1'//nl// &
        'set grid xtics ytics ls 100'//nl// &
        "set title font ',14'"//nl// &
        'set key below horizontal spacing 1.2 width 2'//nl// &
        '# 5 % head room so curves at their extremes do not hide under the frame'//nl// &
        'set offsets 0, 0, graph 0.05, graph 0.05'//nl// &
        '# axes fit the data (plus the offsets above) instead of growing to the next tic'//nl// &
        'set autoscale fix'//nl// &
        "set xlabel '"//x_label//"'"//nl// &
        'set linetype 1 lc rgb "#1f77b4" lw 2 dt 1'//nl// &
        'set linetype 2 lc rgb "#d62728" lw 2 dt 1'//nl// &
        'set linetype 3 lc rgb "#2ca02c" lw 2 dt 1'//nl// &
        'set linetype 4 lc rgb "#000000" lw 2 dt 2'//nl// &
        'set linetype 5 lc rgb "#9467bd" lw 2 dt 1'//nl// &
        'set linetype 6 lc rgb "#ff7f0e" lw 2 dt 1'//nl// &
        'set linetype 7 lc rgb "#8c564b" lw 2 dt 1'//nl// &
        'set linetype 8 lc rgb "#17becf" lw 2 dt 1'//nl// &
        'set linetype cycle 8'//nl//nl

    ! Positions of the tracked nodes (the thesis' "Time x Position in x of impactor and target
    ! nodes"); nothing to draw when no node is tracked.
    if (nk > 0) then
      do a = 1, 3
        s = s//'# '//axis(a)//' position of every tracked node'//nl// &
            "set output 'positions_"//axis(a)//".png'"//nl// &
            "set title 'Position in "//axis(a)//" of the tracked nodes"//versus//"'"//nl// &
            "set ylabel '"//axis(a)//" [m]'"//nl//'plot '
        do k = 1, nk
          v = 'c_p'//itoa(k)//'_'//axis(a)
          if (k > 1) s = s//', \'//nl//'     '
          s = s//"datafile @rows using (ms(c_t)):(column("//v//")) with lines lt "//itoa(k) &
              //" title '"//gp_quote(labels(k)%s)//"'"
        end do
        s = s//nl//nl
      end do
      ! Displacements show what positions metres apart hide (the spheres move by centimetres);
      ! each curve is taken from its own first row (gnuplot reads the curves one by one).
      s = s//'# x, y, z displacement of every tracked node from its first row'//nl// &
          'set terminal @term size 1000,1100'//nl// &
          "set output 'displacements.png'"//nl// &
          "set multiplot layout 3,1 title 'Displacement of the tracked nodes"//versus//"' font ',15'"//nl
      do a = 1, 3
        s = s//"set title '"//axis(a)//"'"//nl//"set ylabel 'u_"//axis(a)//" [m]'"//nl
        if (a == 3) s = s//'set key below horizontal spacing 1.2 width 2'//nl
        if (a < 3) s = s//'unset key'//nl
        s = s//'plot '
        do k = 1, nk
          v = 'c_p'//itoa(k)//'_'//axis(a)
          if (k > 1) s = s//', \'//nl//'     '
          s = s//"datafile @rows using (ms(c_t)):($0 == 0 ? (u0 = column("//v//"), 0) : column("//v// &
              ") - u0) with lines lt "//itoa(k)//" title '"//gp_quote(labels(k)%s)//"'"
        end do
        s = s//nl
      end do
      s = s//'unset multiplot'//nl//'set terminal @term size 1000,600'//nl//nl
    else
      s = s//'# No tracked nodes in history.dat: no position plots.'//nl//nl
    end if

    s = s//'# Energy balance'//nl// &
        "set output 'energy.png'"//nl// &
        "set title 'Energies"//versus//"'"//nl// &
        "set ylabel 'energy [J]'"//nl// &
        "plot datafile @rows using (ms(c_t)):(column(c_kinetic)) with lines lt 1 title 'kinetic', \"//nl// &
        "     datafile @rows using (ms(c_t)):(column(c_strain)) with lines lt 2 title 'strain', \"//nl// &
        "     datafile @rows using (ms(c_t)):(column(c_work)) with lines lt 3 title 'work', \"//nl// &
        "     datafile @rows using (ms(c_t)):(column(c_total)) with lines lt 4 title 'total'"//nl//nl

    s = s//'# Linear (top) and angular (bottom) momentum'//nl// &
        'set terminal @term size 1000,800'//nl// &
        "set output 'momentum.png'"//nl// &
        "set multiplot layout 2,1 title 'Momentum"//versus//"' font ',15'"//nl// &
        "set title 'linear momentum'"//nl// &
        "set ylabel 'p [kg"//mdot//"m/s]'"//nl// &
        "plot datafile @rows using (ms(c_t)):(column(c_px)) with lines lt 1 title 'px', \"//nl// &
        "     datafile @rows using (ms(c_t)):(column(c_py)) with lines lt 2 title 'py', \"//nl// &
        "     datafile @rows using (ms(c_t)):(column(c_pz)) with lines lt 3 title 'pz'"//nl// &
        "set title 'angular momentum (about the origin)'"//nl// &
        "set ylabel 'L [kg"//mdot//"m"//sup2//"/s]'"//nl// &
        "plot datafile @rows using (ms(c_t)):(column(c_Lx)) with lines lt 1 title 'Lx', \"//nl// &
        "     datafile @rows using (ms(c_t)):(column(c_Ly)) with lines lt 2 title 'Ly', \"//nl// &
        "     datafile @rows using (ms(c_t)):(column(c_Lz)) with lines lt 3 title 'Lz'"//nl// &
        'unset multiplot'//nl// &
        'set terminal @term size 1000,600'//nl//nl

    ! Counts are integers: integer tick steps, and a y range that starts at 0 and is not empty
    ! when nothing is in contact (gnuplot would warn about an empty range).
    s = s//'# Contact: number of active contacts (left axis), total contact force (right axis)'//nl// &
        "stats datafile @rows using c_contacts nooutput name 'CONT'"//nl// &
        "stats datafile @rows using c_fcontact nooutput name 'FCON'"//nl// &
        "set output 'contact.png'"//nl// &
        "set title 'Contact"//versus//"'"//nl// &
        "set ylabel 'active contacts [-]' textcolor lt 1"//nl// &
        "set y2label 'total contact force [N]' textcolor lt 2"//nl// &
        'set yrange [0:imax(1, CONT_max*1.1)]'//nl// &
        'set ytics nomirror imax(1, ceil(CONT_max/8.0))'//nl// &
        'if (FCON_max > FCON_min) {'//nl// &
        '  set y2range [(FCON_min < 0 ? 1.1*FCON_min : 0):FCON_max + 0.1*(FCON_max - FCON_min)]'//nl// &
        '} else {'//nl// &
        '  set y2range [(FCON_min < 0 ? FCON_min - 1 : 0):FCON_max + 1]'//nl// &
        '}'//nl// &
        'set y2tics'//nl// &
        'set grid noy2tics'//nl// &
        "plot datafile @rows using (ms(c_t)):(column(c_contacts)) with steps lt 1 title 'active contacts (left axis)', \"//nl// &
        "     datafile @rows using (ms(c_t)):(column(c_fcontact)) axes x1y2 with lines lt 2 "// &
        "title 'contact force (right axis)'"//nl// &
        'unset y2tics; unset y2label; set ylabel textcolor default'//nl// &
        'set ytics mirror autofreq; set yrange [*:*]'//nl//nl

    s = s//'# Newton iterations per time step'//nl// &
        "stats datafile @rows using c_newton nooutput name 'NEWT'"//nl// &
        "set output 'newton.png'"//nl// &
        "set title 'Newton iterations per time step'"//nl// &
        "set ylabel 'Newton iterations [-]'"//nl// &
        'set yrange [0:imax(1, NEWT_max+1)]'//nl// &
        'set ytics imax(1, ceil(NEWT_max/10.0))'//nl// &
        "plot datafile @rows using (ms(c_t)):(column(c_newton)) with steps lt 1 title 'iterations'"//nl// &
        'set ytics autofreq; set yrange [*:*]'//nl// &
        'unset output'//nl
  end function gnuplot_script

  !> Write s to path (replacing it).
  subroutine write_text(path, s, err)
    character(len=*), intent(in) :: path, s
    type(error_t), allocatable, intent(out) :: err
    character(len=msg_len) :: msg
    integer :: u, ios
    open (newunit=u, file=path, status='replace', action='write', form='formatted', &
          iostat=ios, iomsg=msg)
    if (ios == 0) write (u, '(a)', iostat=ios, iomsg=msg) s
    if (ios == 0) then
      close (u, iostat=ios, iomsg=msg)
    else
      close (u)
    end if
    if (ios /= 0) call fatal_error(err, 'make_plots: cannot write '//path//': '//trim(msg))
  end subroutine write_text

  !> Read one line of any length; ios = 0 on success, non-zero at end of file (a last line
  !> without newline still counts as a line).
  subroutine read_line(u, line, ios)
    integer, intent(in) :: u
    character(len=:), allocatable, intent(out) :: line
    integer, intent(out) :: ios
    character(len=1024) :: buf
    integer :: sz
    logical :: got
    line = ''
    got = .false.
    do
      read (u, '(a)', advance='no', iostat=ios, size=sz) buf
      if (sz > 0) got = .true.
      line = line//buf(:sz)
      if (ios /= 0) exit
    end do
    if (is_iostat_eor(ios)) ios = 0
    if (is_iostat_end(ios) .and. got) ios = 0
  end subroutine read_line

  !> Split a line at blanks, tabs and carriage returns.
  function split(line) result(w)
    character(len=*), intent(in) :: line
    type(word_t), allocatable :: w(:)
    integer :: i, n, start, pass
    do pass = 1, 2
      n = 0
      start = 0
      do i = 1, len(line) + 1
        if (i <= len(line)) then
          if (.not. is_space(line(i:i))) then
            if (start == 0) start = i
            cycle
          end if
        end if
        if (start > 0) then
          n = n + 1
          if (pass == 2) w(n)%s = line(start:i - 1)
          start = 0
        end if
      end do
      if (pass == 1) allocate (w(n))
    end do
  end function split

  pure logical function is_space(c)
    character(len=1), intent(in) :: c
    is_space = c == ' ' .or. c == achar(9) .or. c == achar(13)
  end function is_space

  !> Index of the first word equal to name, 0 if none.
  pure integer function find(w, name)
    type(word_t), intent(in) :: w(:)
    character(len=*), intent(in) :: name
    integer :: i
    find = 0
    do i = 1, size(w)
      if (w(i)%s == name) then
        find = i
        return
      end if
    end do
  end function find

  !> dir without trailing slashes ('.' for an empty name, '/' kept).
  pure function clean_dir(dir) result(d)
    character(len=*), intent(in) :: dir
    character(len=:), allocatable :: d
    integer :: n
    n = len_trim(dir)
    do while (n > 1)
      if (dir(n:n) /= '/') exit
      n = n - 1
    end do
    if (n == 0) then
      d = '.'
    else
      d = dir(:n)
    end if
  end function clean_dir

  !> s as one POSIX shell word: inside '...' nothing is special except ' itself, written '\''.
  pure function shell_quote(s) result(q)
    character(len=*), intent(in) :: s
    character(len=:), allocatable :: q
    integer :: i
    q = "'"
    do i = 1, len(s)
      if (s(i:i) == "'") then
        q = q//"'\''"
      else
        q = q//s(i:i)
      end if
    end do
    q = q//"'"
  end function shell_quote

  !> Body of a gnuplot single-quoted string. ' is written as the typographic apostrophe
  !> U+2019: gnuplot's '' escape fails where two meet (a name with '' ended the string).
  pure function gp_quote(s) result(q)
    character(len=*), intent(in) :: s
    character(len=:), allocatable :: q
    integer :: i
    q = ''
    do i = 1, len(s)
      if (s(i:i) == "'") then
        q = q//char(226)//char(128)//char(153)
      else if (iachar(s(i:i)) < 32) then
        q = q//' '            ! control characters would end or garble the command
      else
        q = q//s(i:i)
      end if
    end do
  end function gp_quote

  !> Text for a gnuplot comment line: no control characters (a newline would end it).
  pure function comment_safe(s) result(q)
    character(len=*), intent(in) :: s
    character(len=:), allocatable :: q
    integer :: i
    q = s
    do i = 1, len(q)
      if (iachar(q(i:i)) < 32) q(i:i) = ' '
    end do
  end function comment_safe

  pure function untab(s) result(q)
    character(len=*), intent(in) :: s
    character(len=:), allocatable :: q
    integer :: i
    q = s
    do i = 1, len(q)
      if (q(i:i) == achar(9) .or. q(i:i) == achar(13)) q(i:i) = ' '
    end do
  end function untab
end module casca_plots
