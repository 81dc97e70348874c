!> make_plots on a synthetic history.dat: every PNG is produced and is a real PNG, the script
!> is left for the user, and bad input (no header, empty file, wrong columns, missing folder)
!> comes back as an error naming the file. gnuplot must be installed: its absence is a FAIL.
!> Usage: test_plots FOLDER   (FOLDER is created if needed; files are written inside it)
program test_plots
  use casca_kinds, only: dp, pi
  use casca_error, only: error_t
  use casca_plots, only: make_plots
  implicit none

  character(len=*), parameter :: pngs(8) = [character(len=17) :: 'positions_x.png', &
    'positions_y.png', 'positions_z.png', 'displacements.png', 'energy.png', 'momentum.png', &
    'contact.png', 'newton.png']
  integer :: npass = 0, nfail = 0
  character(len=:), allocatable :: root, d
  type(error_t), allocatable :: err
  logical :: missing
  integer :: i, n

  if (command_argument_count() < 1) then
    print '(a)', 'usage: test_plots FOLDER'
    error stop 2
  end if
  call get_command_argument(1, length=n)
  allocate (character(len=n) :: root)
  call get_command_argument(1, root)

  ! 1. Two tracked nodes with labels: all plots.
  d = root//'/run2'
  call prepare(d)
  call write_history(d//'/history.dat', 2, 400)
  call write_file(d//'/tracked.txt', 'ring1 impactor'//achar(10)//'ring2 target')
  call make_plots(d, err, missing)
  call check('K=2: no error'//err_text(err), .not. allocated(err))
  call check('K=2: gnuplot is installed', .not. missing)
  call check('K=2: plots.gp written', exists(d//'/plots.gp'))
  call check('K=2: plots.gp uses the tracked.txt labels', &
             file_has(d//'/plots.gp', "'ring2 target'"))
  do i = 1, size(pngs)
    call check('K=2: '//trim(pngs(i))//' is a PNG', is_png(d//'/'//trim(pngs(i))))
  end do

  ! 2. One node, no tracked.txt, a folder name the shell must not misread: default labels.
  d = root//"/it's a run; ls"
  call prepare(d)
  call write_history(d//'/history.dat', 1, 50)
  call make_plots(d//'/', err, missing)
  call check('K=1, odd folder name: no error'//err_text(err), .not. allocated(err))
  call check('K=1: default label "node 1"', file_has(d//'/plots.gp', "'node 1'"))
  do i = 1, size(pngs)
    call check('K=1: '//trim(pngs(i))//' is a PNG', is_png(d//'/'//trim(pngs(i))))
  end do

  ! 3. Bad input.
  d = root//'/noheader'
  call prepare(d)
  call write_file(d//'/history.dat', '0.0 1 2 3'//achar(10)//'1.0 2 3 4')
  call make_plots(d, err)
  call check('no header: error naming the file'//err_text(err), names_file(err, d//'/history.dat'))

  d = root//'/empty'
  call prepare(d)
  call write_file(d//'/history.dat', '')
  call make_plots(d, err)
  call check('empty history.dat: error naming the file'//err_text(err), &
             names_file(err, d//'/history.dat'))

  d = root//'/nonewton'
  call prepare(d)
  call write_file(d//'/history.dat', '# t step kinetic strain work total px py pz Lx Ly Lz contacts' &
                  //' fcontact'//achar(10)//'0 0 0 0 0 0 0 0 0 0 0 0 0 0')
  call make_plots(d, err)
  call check('no "newton" column: error naming the file'//err_text(err), &
             names_file(err, d//'/history.dat'))

  d = root//'/shortrow'
  call prepare(d)
  call write_file(d//'/history.dat', header(1)//achar(10)//'0 1 2')
  call make_plots(d, err)
  call check('row shorter than header: error naming the file'//err_text(err), &
             names_file(err, d//'/history.dat'))

  d = root//'/does_not_exist'
  call make_plots(d, err)
  call check('missing folder: error naming the file'//err_text(err), &
             names_file(err, d//'/history.dat'))

  print '(i0,a,i0,a)', npass, ' passed, ', nfail, ' failed'
  if (nfail > 0) error stop 1

contains

  subroutine check(name, ok)
    character(len=*), intent(in) :: name
    logical, intent(in) :: ok
    if (ok) then
      npass = npass + 1
      print '(a,a)', 'PASS ', name
    else
      nfail = nfail + 1
      print '(a,a)', 'FAIL ', name
    end if
  end subroutine check

  !> ' (message)' to show what an error said, '' if none.
  function err_text(e) result(s)
    type(error_t), allocatable, intent(in) :: e
    character(len=:), allocatable :: s
    s = ''
    if (allocated(e)) s = ' ['//e%message//']'
  end function err_text

  logical function names_file(e, path)
    type(error_t), allocatable, intent(in) :: e
    character(len=*), intent(in) :: path
    names_file = .false.
    if (allocated(e)) names_file = index(e%message, path) > 0
  end function names_file

  !> Create folder d and remove outputs of an earlier run, so nothing stale passes a check.
  subroutine prepare(d)
    character(len=*), intent(in) :: d
    integer :: stat, cstat, i
    call execute_command_line('mkdir -p '//shell_quote(d), exitstat=stat, cmdstat=cstat)
    if (cstat /= 0 .or. stat /= 0) then
      print '(a)', 'cannot create folder '//d
      error stop 2
    end if
    do i = 1, size(pngs)
      call remove(d//'/'//trim(pngs(i)))
    end do
    call remove(d//'/plots.gp')
    call remove(d//'/tracked.txt')
  end subroutine prepare

  subroutine remove(path)
    character(len=*), intent(in) :: path
    integer :: u, ios
    if (.not. exists(path)) return
    open (newunit=u, file=path, status='old', iostat=ios)
    if (ios == 0) close (u, status='delete')
  end subroutine remove

  logical function exists(path)
    character(len=*), intent(in) :: path
    inquire (file=path, exist=exists)
  end function exists

  !> The first 8 bytes are the PNG signature 89 50 4E 47 0D 0A 1A 0A.
  logical function is_png(path)
    character(len=*), intent(in) :: path
    character(len=8) :: sig
    integer :: u, ios
    is_png = .false.
    open (newunit=u, file=path, status='old', access='stream', form='unformatted', &
          action='read', iostat=ios)
    if (ios /= 0) return
    read (u, iostat=ios) sig
    close (u)
    is_png = ios == 0 .and. sig == char(137)//'PNG'//achar(13)//achar(10)//achar(26)//achar(10)
  end function is_png

  !> Whether a text file contains s somewhere (line by line; lines here are short).
  logical function file_has(path, s)
    character(len=*), intent(in) :: path, s
    character(len=4096) :: line
    integer :: u, ios
    file_has = .false.
    open (newunit=u, file=path, status='old', action='read', iostat=ios)
    if (ios /= 0) return
    do
      read (u, '(a)', iostat=ios) line
      if (ios /= 0) exit
      if (index(line, s) > 0) then
        file_has = .true.
        exit
      end if
    end do
    close (u)
  end function file_has

  subroutine write_file(path, text)
    character(len=*), intent(in) :: path, text
    integer :: u
    open (newunit=u, file=path, status='replace', action='write')
    write (u, '(a)') text
    close (u)
  end subroutine write_file

  function header(nk) result(h)
    integer, intent(in) :: nk
    character(len=:), allocatable :: h
    character(len=16) :: c
    integer :: k
    h = '# t step kinetic strain work total px py pz Lx Ly Lz contacts fcontact newton'
    do k = 1, nk
      write (c, '(i0)') k
      associate (p => ' p'//trim(c)//'_')
        h = h//p//'x'//p//'y'//p//'z'//p//'vx'//p//'vy'//p//'vz'
      end associate
    end do
  end function header

  !> A made-up impact of 20 ms: nodes oscillating about known positions, contact between 5
  !> and 15 ms with a force pulse, energy exchanged between kinetic and strain.
  subroutine write_history(path, nk, nrow)
    character(len=*), intent(in) :: path
    integer, intent(in) :: nk, nrow
    real(dp), parameter :: period = 0.01_dp, tend = 0.02_dp
    real(dp) :: t, w, s, ek, es, wk, px, lz, fc, x(3), v(3)
    integer :: u, i, k, nc, nit
    open (newunit=u, file=path, status='replace', action='write')
    write (u, '(a)') header(nk)
    w = 2*pi/period
    do i = 1, nrow
      t = (i - 1)*tend/nrow
      s = 0
      if (t > 0.005_dp .and. t < 0.015_dp) s = sin(pi*(t - 0.005_dp)/0.01_dp)
      ek = 100*cos(pi*t/tend)**2
      es = 95*sin(pi*t/tend)**2
      wk = 5*t/tend
      px = 2 - 0.8*s
      lz = 0.05*sin(w*t)
      fc = 3000*s**2
      nc = nint(12*s)
      nit = 2 + nint(3*s)
      write (u, '(es23.15,1x,i0,10(1x,es23.15),1x,i0,1x,es23.15,1x,i0)', advance='no') &
        t, i - 1, ek, es, wk, ek + es + wk, px, 0.1_dp*s, 0.0_dp, 0.0_dp, 0.0_dp, lz, nc, fc, nit
      do k = 1, nk
        x = [1 + 0.05*(k - 1) + 0.01*sin(w*t + k), 0.02*cos(w*t/2)/k, 0.001*k*t/tend]
        v = [0.01*w*cos(w*t + k), -0.01*w*sin(w*t/2)/k, 0.001*k/tend]
        write (u, '(6(1x,es23.15))', advance='no') x, v
      end do
      write (u, '(a)') ''
    end do
    close (u)
  end subroutine write_history

  function shell_quote(s) result(q)
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
end program test_plots
