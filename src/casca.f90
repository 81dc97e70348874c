!> casca: impact between elastic shell structures (positional shell FEM, Newmark,
!> signed-distance contact with Lagrange multipliers). The command line picks one of
!> run / check / mesh / plot.
program casca
  use, intrinsic :: iso_c_binding, only: c_int
  use casca_kinds, only: dp
  use casca_error, only: error_t
  use casca_mpi, only: mpi_start, mpi_stop, is_root, max_all
  use casca_run, only: run_deck, load_scene, exit_ok, exit_input
  use casca_deck, only: deck_t
  use casca_model, only: model_t
  use casca_mesh, only: mesh_t
  use casca_mesh_generators, only: mesh_ring, mesh_sphere, mesh_plate
  use casca_gmsh_io, only: write_gmsh
  use casca_plots, only: make_plots
  implicit none

  interface
    subroutine c_exit(status) bind(c, name='exit')
      import :: c_int
      integer(c_int), value :: status
    end subroutine c_exit
  end interface

  character(len=*), parameter :: version = '0.1.0'
  character(len=:), allocatable :: cmd
  integer :: code

  call mpi_start()
  code = exit_ok
  cmd = arg(1)
  select case (cmd)
  case ('run')
    call cmd_run()
  case ('check')
    call cmd_check()
  case ('mesh')
    call cmd_mesh()
  case ('plot')
    call cmd_plot()
  case ('--version', '-V')
    if (is_root()) print '(a)', 'casca '//version
  case ('--help', '-h', 'help')
    call usage(6)
  case ('')
    call usage(0); code = exit_input
  case default
    if (is_root()) write (0, '(a)') 'error: unknown command "'//cmd//'" (see casca --help)'
    code = exit_input
  end select
  call max_all(code)   ! an error seen on one rank only (casca mesh, casca plot) ends all alike
  call mpi_stop()
  call c_exit(int(code, c_int))   ! a plain exit code, no "STOP n" line, no backtrace

contains

  function arg(i) result(s)
    integer, intent(in) :: i
    character(len=:), allocatable :: s
    integer :: n
    call get_command_argument(i, length=n)
    allocate (character(len=n) :: s)
    if (n > 0) call get_command_argument(i, s)
  end function arg

  subroutine usage(u)
    integer, intent(in) :: u
    if (.not. is_root()) return
    write (u, '(a)') 'casca '//version//': impact between elastic shell structures', &
      '', 'usage:', &
      '  casca run DECK [--out DIR] [--restart FILE] [-q]   run a deck (also under mpirun -np N)', &
      '  casca check DECK                                 check a deck without running it', &
      '  casca mesh ring   --radius R --width W --n-around N --n-across M -o FILE.msh', &
      '  casca mesh sphere --radius R --n-div N -o FILE.msh', &
      '  casca mesh plate|strip --lx A --ly B --nx N --ny M -o FILE.msh', &
      '  casca plot DIR                                   (re)make the plots of a finished run', &
      '  casca --help | --version', &
      '', 'exit codes: 0 done, 2 bad input, 3 the solver could not go on (last state kept)'
  end subroutine usage

  subroutine cmd_run()
    character(len=:), allocatable :: deck, out, restart, a
    logical :: quiet
    integer :: i
    deck = ''; out = ''; restart = ''; quiet = .false.
    i = 2
    do while (i <= command_argument_count())
      a = arg(i)
      if ((a == '--out' .or. a == '-o' .or. a == '--restart') .and. &
          i == command_argument_count()) then
        if (is_root()) write (0, '(a)') 'error: run: '//a//' needs a value'
        code = exit_input; return
      end if
      select case (a)
      case ('--out', '-o')
        i = i + 1; out = arg(i)
      case ('--restart')
        i = i + 1; restart = arg(i)
      case ('-q', '--quiet')
        quiet = .true.
      case default
        if (a(1:1) == '-' .or. deck /= '') then
          if (is_root()) write (0, '(a)') 'error: run: unexpected argument "'//a//'"'
          code = exit_input; return
        end if
        deck = a
      end select
      i = i + 1
    end do
    if (deck == '') then
      if (is_root()) write (0, '(a)') 'error: run: no deck given (casca run DECK)'
      code = exit_input; return
    end if
    call run_deck(deck, out, restart, quiet, code)
  end subroutine cmd_run

  subroutine cmd_check()
    type(deck_t) :: deck
    type(model_t) :: model
    if (command_argument_count() /= 2) then
      if (is_root()) write (0, '(a)') 'error: check: usage: casca check DECK'
      code = exit_input; return
    end if
    call load_scene(arg(2), deck, model, code, gaps=.true.)
    if (code == exit_ok .and. is_root()) print '(a,i0,a,i0,a,i0,a,i0,a)', arg(2)//': ok: ', &
      model%nbody, ' bodies, ', model%nelem, ' elements, ', model%nnode, ' nodes, ', &
      count(.not. model%fixed), ' unknowns'
  end subroutine cmd_check

  subroutine cmd_mesh()
    type(mesh_t) :: mesh
    type(error_t), allocatable :: err
    character(len=:), allocatable :: kind, out, key, val
    real(dp) :: radius, width, lx, ly
    integer :: n_around, n_across, n_div, nx, ny, i, ios
    kind = arg(2); out = ''
    radius = 1; width = 0.2_dp; lx = 1; ly = 1; n_around = 20; n_across = 1; n_div = 6
    nx = 4; ny = 1
    i = 3
    do while (i <= command_argument_count())
      key = arg(i)
      if (i + 1 > command_argument_count()) then
        if (is_root()) write (0, '(a)') 'error: mesh: '//key//' needs a value'
        code = exit_input; return
      end if
      ios = 0
      select case (key)
      case ('-o', '--out'); out = arg(i + 1)
      case ('--radius'); val = arg(i + 1); read (val, *, iostat=ios) radius
      case ('--width'); val = arg(i + 1); read (val, *, iostat=ios) width
      case ('--lx'); val = arg(i + 1); read (val, *, iostat=ios) lx
      case ('--ly'); val = arg(i + 1); read (val, *, iostat=ios) ly
      case ('--n-around'); val = arg(i + 1); read (val, *, iostat=ios) n_around
      case ('--n-across'); val = arg(i + 1); read (val, *, iostat=ios) n_across
      case ('--n-div'); val = arg(i + 1); read (val, *, iostat=ios) n_div
      case ('--nx'); val = arg(i + 1); read (val, *, iostat=ios) nx
      case ('--ny'); val = arg(i + 1); read (val, *, iostat=ios) ny
      case default
        if (is_root()) write (0, '(a)') 'error: mesh: unknown option '//key
        code = exit_input; return
      end select
      if (ios /= 0) then
        if (is_root()) write (0, '(a)') 'error: mesh: '//key//' expects a number, got "'// &
          arg(i + 1)//'"'
        code = exit_input; return
      end if
      i = i + 2
    end do
    if (out == '') then
      if (is_root()) write (0, '(a)') 'error: mesh: give the output file with -o FILE.msh'
      code = exit_input; return
    end if
    select case (kind)
    case ('ring')
      call mesh_ring(radius, width, n_around, n_across, mesh, err)
    case ('sphere')
      call mesh_sphere(radius, n_div, mesh, err)
    case ('plate', 'strip')
      call mesh_plate(lx, ly, nx, ny, mesh, err)
    case default
      if (is_root()) write (0, '(a)') 'error: mesh: unknown kind "'//kind// &
        '" (ring, sphere, plate, strip)'
      code = exit_input; return
    end select
    if (.not. allocated(err) .and. is_root()) call write_gmsh(out, mesh, err)
    if (allocated(err)) then
      if (is_root()) write (0, '(a)') 'error: mesh: '//err%message
      code = exit_input; return
    end if
    if (is_root()) print '(a,i0,a,i0,a)', out//': ', mesh%nelem, ' elements, ', mesh%nnode, ' nodes'
  end subroutine cmd_mesh

  subroutine cmd_plot()
    type(error_t), allocatable :: err
    logical :: missing
    if (command_argument_count() /= 2) then
      if (is_root()) write (0, '(a)') 'error: plot: usage: casca plot DIR'
      code = exit_input; return
    end if
    if (.not. is_root()) return
    call make_plots(arg(2), err, missing)
    if (allocated(err)) then
      write (0, '(a)') 'error: plot: '//err%message
      code = exit_input
    else if (missing) then
      write (0, '(a)') 'error: gnuplot is not installed; '//arg(2)//'/plots.gp was written'
      code = exit_input
    else
      print '(a)', 'plots written in '//arg(2)
    end if
  end subroutine cmd_plot
end program casca
