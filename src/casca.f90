!> casca: impact between elastic shell structures (positional shell FEM, Newmark,
!> signed-distance contact with Lagrange multipliers). The command line picks one of
!> run / check / mesh / plot; `casca COMMAND --help` tells each one's options.
!>
!> Preprocessed (cpp) for the build facts of casca --version: CMake defines CASCA_BUILD_INFO
!> and generates casca_build_info.h at every build (the git commit, the build type); other
!> builds (fpm) fall back to 'unknown'.
#ifdef CASCA_BUILD_INFO
#include "casca_build_info.h"
#endif
#ifndef CASCA_GIT_COMMIT
#define CASCA_GIT_COMMIT "unknown"
#endif
#ifndef CASCA_BUILD_TYPE
#define CASCA_BUILD_TYPE "unknown"
#endif
program casca
  use, intrinsic :: iso_c_binding, only: c_int
  use, intrinsic :: iso_fortran_env, only: compiler_version
  use casca_kinds, only: dp
  use casca_error, only: error_t
  use casca_strings, only: count_of, itoa
  use casca_mpi, only: mpi_start, mpi_stop, is_root, max_all, mpi_version
  use casca_mumps_solver, only: mumps_version
  use casca_hdf5_io, only: hdf5_version
  use casca_run, only: run_deck, load_scene, exit_ok, exit_input
  use casca_deck, only: deck_t, body_cfg_t, counts_for_size, unset
  use casca_model, only: model_t
  use casca_mesh, only: mesh_t
  use casca_mesh_generators, only: generated_mesh
  use casca_gmsh_io, only: write_gmsh
  use casca_plots, only: make_plots
  use casca_starter, only: starter_report
  implicit none

  interface
    subroutine c_exit(status) bind(c, name='exit')
      import :: c_int
      integer(c_int), value :: status
    end subroutine c_exit
    !> metis.h's version numbers (src/solve/metis_check.c)
    subroutine metis_version_c(major, minor, subminor) bind(c, name='casca_metis_version')
      import :: c_int
      integer(c_int), intent(out) :: major, minor, subminor
    end subroutine metis_version_c
  end interface

  character(len=*), parameter :: version = '0.1.0'
  character(len=*), parameter :: commands(4) = [character(len=5) :: 'run', 'check', 'mesh', 'plot']
  !> width of a line of help text
  integer, parameter :: hw = 100
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
    call print_version()
  case ('--help', '-h')
    call usage(6)
  case ('help')   ! casca help [COMMAND]
    if (command_argument_count() < 2) then
      call usage(6)
    else if (any(commands == arg(2))) then
      call command_help(arg(2))
    else
      if (is_root()) write (0, '(a)') 'error: help: unknown command "'//arg(2)// &
        '" (commands: run, check, mesh, plot)'
      code = exit_input
    end if
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

  !> casca --help: every command's synopsis, as its own help text gives it
  subroutine usage(u)
    integer, intent(in) :: u
    character(len=hw), allocatable :: t(:)
    integer :: c, k
    if (.not. is_root()) return
    write (u, '(a)') 'casca '//version//': impact between elastic shell structures', '', 'usage:'
    do c = 1, size(commands)
      t = help_text(trim(commands(c)))
      do k = 1, size(t)
        if (t(k) == '') exit
        write (u, '(a)') '  '//trim(t(k))
      end do
    end do
    write (u, '(a)') '  casca COMMAND --help                               the options of a command', &
      '  casca --help | --version', &
      '', 'exit codes: 0 done, 2 bad input, 3 the solver could not go on (last state kept),', &
      '  4 stopped by a signal (state kept)'
  end subroutine usage

  !> casca COMMAND --help (and casca help COMMAND): the command's whole help text, on stdout
  subroutine command_help(cmd)
    character(len=*), intent(in) :: cmd
    character(len=hw), allocatable :: t(:)
    integer :: k
    logical :: synopsis
    if (.not. is_root()) return
    t = help_text(cmd)
    write (6, '(a)') 'usage:'
    synopsis = .true.
    do k = 1, size(t)
      if (t(k) == '') synopsis = .false.
      if (synopsis) then
        write (6, '(a)') '  '//trim(t(k))
      else
        write (6, '(a)') trim(t(k))
      end if
    end do
  end subroutine command_help

  !> True if -h or --help is among the command's arguments (after the command's name)
  logical function wants_help()
    integer :: i
    wants_help = .false.
    do i = 2, command_argument_count()
      if (arg(i) == '-h' .or. arg(i) == '--help') wants_help = .true.
    end do
  end function wants_help

  !> The one help text of each command: its synopsis lines up to the first blank line (what
  !> casca --help lists), then what it does, its options and what it writes.
  function help_text(cmd) result(t)
    character(len=*), intent(in) :: cmd
    character(len=hw), allocatable :: t(:)
    select case (cmd)
    case ('run')
      t = [character(len=hw) :: &
        'casca run DECK [--out DIR] [--restart FILE] [-q]   run a deck (also under mpirun -np N)', &
        '', &
        'Runs the scene of the namelist deck DECK (its mesh files are relative to the deck).', &
        'options:', &
        '  -o, --out DIR     output folder (default: dir of the deck''s &output, else out;', &
        '                    relative to the current folder)', &
        '  --restart FILE    continue from a checkpoint of the same model (DIR/checkpoint.h5)', &
        '  -q, --quiet       no progress lines and no closing summary (errors still shown)', &
        '  -h, --help        this text', &
        'prints a progress line per frame and a closing summary: the time taken, (dynamics) what was', &
        '  kept and the energy balance, and each body''s mesh indicator (where its mesh is coarsest,', &
        '  and a relative error estimate of its stress resultants: docs/mesh_indicator.md)', &
        'writes in the output folder:', &
        '  run.pvd, frame_NNNNN.vtu    ParaView frames with their times', &
        '  history.dat, history.h5     one row per step: energies, momenta, contacts, tracked nodes', &
        '  tracked.txt                 a label per tracked node', &
        '  checkpoint.h5               the state at the last checkpoint (for --restart)', &
        '  plots.gp, *.png             time-history plots (gnuplot), unless &output plots = .false.', &
        '  gnuplot.log                 gnuplot''s messages', &
        '  casca.lock                  while it runs: no second run writes into the folder', &
        '  stopped.txt                 a run that stopped early (exit 3, 4): when, why, where to restart', &
        'exit codes: 0 done, 2 bad input (every problem of the deck listed), 3 the solver could', &
        '  not go on or an output could not be written (the last good state is kept), 4 stopped', &
        '  by SIGTERM, SIGINT or SIGUSR1 at the end of the step under way (its state is kept; under', &
        '  mpirun send SIGUSR1: mpirun kills its ranks a second after a SIGTERM)']
    case ('check')
      t = [character(len=hw) :: &
        'casca check DECK                                   check a deck without running it', &
        '', &
        'Reads DECK and builds its scene: prints the number of bodies, elements, nodes and', &
        'unknowns, and for each contact pair its initial gap and time to contact at the', &
        'initial velocities. Every problem of the deck is listed with its file, line and field.', &
        'Then, per body: nodes, elements, thickness, area, mass, bounding box, whether the mesh', &
        'is closed and its normals point out, the shortest element edge, the worst element', &
        'quality, the membrane wave speed and the explicit step it suggests; the deck''s dt', &
        'against it; the unknowns, matrix entries and memory; a run time on one core, with the', &
        'steps, Newton iterations and factorisations it assumed. Warnings (stderr, exit 0):', &
        'normals into a closed body, distorted elements, pairs that never meet (nothing', &
        'sets them moving), a dt that carries a node across the contact band in one step.', &
        'Writes no file.', &
        'options:', &
        '  -h, --help        this text', &
        'exit codes: 0 the deck can run, 2 it has problems']
    case ('mesh')
      t = [character(len=hw) :: &
        'casca mesh ring   --radius R --width W --n-around N --n-across M -o FILE.msh', &
        'casca mesh sphere --radius R --n-div N -o FILE.msh', &
        'casca mesh plate|strip --lx A --ly B --nx N --ny M -o FILE.msh', &
        'casca mesh KIND ... --size H -o FILE.msh      (counts for cells of sides about H)', &
        '', &
        'Writes a mesh of 10-node (cubic) triangles to FILE.msh (Gmsh MSH 4.1) for a deck''s', &
        '&body mesh = ''file''. Sizes in m; each grid cell is two triangles.', &
        '  ring     cylindrical strip, axis z, mid-surface radius R (1), width W (0.2) along z,', &
        '           N (20) cells around and M (1) across', &
        '  sphere   sphere of radius R (1) about the origin: 20 N^2 triangles, N (6) per', &
        '           icosahedron edge', &
        '  plate    rectangle [0,A] x [0,B] (1 x 1) in the xy plane, N (4) by M (1) cells;', &
        '  strip    the same', &
        'options:', &
        '  --size H          the counts for grid cells of sides at most about H [m] (their', &
        '                    diagonal, also an element edge, is up to 1.41 H), as a deck''s', &
        '                    element_size: ring 2 pi R / H around and W / H across, sphere', &
        '                    (R / sin 72 deg) / H per icosahedron edge (its triangles'' edges), plate', &
        '                    A / H by B / H, rounded up; it replaces the counts given', &
        '  -o, --out FILE    the mesh file to write (required)', &
        '  -h, --help        this text', &
        'exit codes: 0 written, 2 bad input']
    case ('plot')
      t = [character(len=hw) :: &
        'casca plot DIR                                     (re)make the plots of a finished run', &
        '', &
        'Reads DIR/history.dat (and DIR/tracked.txt), writes DIR/plots.gp and runs gnuplot on it', &
        'in DIR: positions_x|y|z.png, displacements.png, energy.png, momentum.png, contact.png,', &
        'newton.png; gnuplot''s messages go to DIR/gnuplot.log. Edit plots.gp and re-run', &
        'gnuplot plots.gp in DIR to change them. A last line cut short (a run killed while', &
        'writing it, a truncated copy) is left out with a warning; any other bad row is an error.', &
        'options:', &
        '  -h, --help        this text', &
        'exit codes: 0 plots written, 2 no readable history or gnuplot missing (plots.gp kept)']
    case default
      allocate (t(0))
    end select
  end function help_text

  !> casca --version: casca's version and build, and the versions of the libraries it was
  !> built with (MUMPS starts an instance, collectively: every rank takes part)
  subroutine print_version()
    character(len=:), allocatable :: mumps
    integer(c_int) :: major, minor, subminor
    mumps = mumps_version()
    call metis_version_c(major, minor, subminor)
    if (.not. is_root()) return
    write (6, '(a)') 'casca '//version, &
      'commit:   '//CASCA_GIT_COMMIT, &
      'build:    '//CASCA_BUILD_TYPE, &
      'compiler: '//compiler_version(), &
      'MPI:      '//mpi_version(), &
      'MUMPS:    '//mumps, &
      'HDF5:     '//hdf5_version(), &
      'METIS:    '//itoa(int(major))//'.'//itoa(int(minor))//'.'//itoa(int(subminor))
  end subroutine print_version

  subroutine cmd_run()
    character(len=:), allocatable :: deck, out, restart, a
    logical :: quiet
    integer :: i
    deck = ''; out = ''; restart = ''; quiet = .false.
    if (wants_help()) then
      call command_help('run'); return
    end if
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
    if (wants_help()) then
      call command_help('check'); return
    end if
    if (command_argument_count() /= 2) then
      if (is_root()) write (0, '(a)') 'error: check: usage: casca check DECK (see casca check --help)'
      code = exit_input; return
    end if
    call load_scene(arg(2), deck, model, code, gaps=.true.)
    if (code == exit_ok .and. is_root()) call starter_report(deck, model, 6, 0)
    if (code == exit_ok .and. is_root() .and. deck%run%title /= '') &
      print '(a)', arg(2)//': '//trim(deck%run%title)
    if (code == exit_ok .and. is_root()) print '(a)', arg(2)//': ok: '// &
      count_of(model%nbody, 'body', 'bodies')//', '//count_of(model%nelem, 'element', 'elements')// &
      ', '//count_of(model%nnode, 'node', 'nodes')//', '// &
      count_of(count(.not. model%fixed), 'unknown', 'unknowns')
  end subroutine cmd_check

  subroutine cmd_mesh()
    type(mesh_t) :: mesh
    type(error_t), allocatable :: err
    character(len=:), allocatable :: out, key, val
    ! the deck's body holds the generator's sizes and defaults, and its rule for element_size
    type(body_cfg_t) :: b
    integer :: i, ios
    if (wants_help()) then
      call command_help('mesh'); return
    end if
    b%mesh = arg(2); out = ''
    i = 3
    do while (i <= command_argument_count())
      key = arg(i)
      if (i + 1 > command_argument_count()) then
        if (is_root()) write (0, '(a)') 'error: mesh: '//key//' needs a value'
        code = exit_input; return
      end if
      ios = 0; val = arg(i + 1)
      select case (key)
      case ('-o', '--out'); out = val
      case ('--radius'); read (val, *, iostat=ios) b%radius
      case ('--width'); read (val, *, iostat=ios) b%width
      case ('--lx'); read (val, *, iostat=ios) b%lx
      case ('--ly'); read (val, *, iostat=ios) b%ly
      case ('--n-around'); read (val, *, iostat=ios) b%n_around
      case ('--n-across'); read (val, *, iostat=ios) b%n_across
      case ('--n-div'); read (val, *, iostat=ios) b%n_div
      case ('--nx'); read (val, *, iostat=ios) b%nx
      case ('--ny'); read (val, *, iostat=ios) b%ny
      case ('--size')
        read (val, *, iostat=ios) b%element_size
        if (ios == 0 .and. .not. (b%element_size > 0 .and. b%element_size < huge(1._dp))) then
          if (is_root()) write (0, '(a)') 'error: mesh: --size must be a positive length, got "'// &
            val//'"'
          code = exit_input; return
        end if
      case default
        if (is_root()) write (0, '(a)') 'error: mesh: unknown option '//key
        code = exit_input; return
      end select
      if (ios /= 0) then
        if (is_root()) write (0, '(a)') 'error: mesh: '//key//' expects a number, got "'// &
          val//'"'
        code = exit_input; return
      end if
      i = i + 2
    end do
    ! --size wins over the counts, given before or after it
    if (b%element_size /= unset) call counts_for_size(b)
    if (out == '') then
      if (is_root()) write (0, '(a)') 'error: mesh: give the output file with -o FILE.msh'
      code = exit_input; return
    end if
    call generated_mesh(b, mesh, err)
    if (.not. allocated(err) .and. is_root()) call write_gmsh(out, mesh, err)
    if (allocated(err)) then
      if (is_root()) write (0, '(a)') 'error: mesh: '//err%message
      code = exit_input; return
    end if
    if (is_root()) print '(a)', out//': '//count_of(mesh%nelem, 'element', 'elements')//', '// &
      count_of(mesh%nnode, 'node', 'nodes')
  end subroutine cmd_mesh

  subroutine cmd_plot()
    type(error_t), allocatable :: err
    character(len=:), allocatable :: note
    logical :: missing
    if (wants_help()) then
      call command_help('plot'); return
    end if
    if (command_argument_count() /= 2) then
      if (is_root()) write (0, '(a)') 'error: plot: usage: casca plot DIR (see casca plot --help)'
      code = exit_input; return
    end if
    if (.not. is_root()) return
    call make_plots(arg(2), err, missing, note=note)
    if (allocated(note)) write (0, '(a)') 'warning: plot: '//note
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
