!> One run per output folder. The run that writes DIR holds DIR/casca.lock, created
!> exclusively (Fortran's status='new' is open(2) with O_CREAT|O_EXCL, so of two runs exactly
!> one gets it) and holding its process id; a second run is refused before it touches a file.
!> A lock left by a run that died (kill -9, power cut) names a process that no longer exists
!> (kill(pid, 0) fails) or is a zombie, dead but not yet reaped (Linux's /proc/PID/stat says
!> Z: a run killed under a container's init stayed so for about a second, and a restart at once
!> was refused): it is taken over, and the caller tells the user so.
module casca_output_lock
  use, intrinsic :: iso_c_binding, only: c_int
  use casca_error, only: error_t, fatal_error
  use casca_files, only: delete_file
  use casca_strings, only: itoa
  implicit none
  private
  public :: lock_folder, unlock_folder, locked_here

  character(len=*), parameter :: lock_name = '/casca.lock'

  interface
    function c_getpid() bind(c, name='getpid') result(pid)
      import :: c_int
      integer(c_int) :: pid
    end function c_getpid

    function c_kill(pid, sig) bind(c, name='kill') result(stat)
      import :: c_int
      integer(c_int), value :: pid, sig
      integer(c_int) :: stat
    end function c_kill
  end interface

contains

  !> Take the lock of folder dir (which exists). note: '' or what the user should be told.
  subroutine lock_folder(dir, note, err)
    character(len=*), intent(in) :: dir
    character(len=:), allocatable, intent(out) :: note
    type(error_t), allocatable, intent(out) :: err
    logical :: got
    integer :: pid

    note = ''
    call try_lock(dir, got, err)
    if (got .or. allocated(err)) return
    pid = holder(dir)
    if (pid <= 0) then   ! empty: a run is writing its pid this very moment, or died doing so
      call fatal_error(err, dir//lock_name//' exists without a process id: another run may '// &
                       'be starting in '//dir//'; if none is, remove the file')
      return
    end if
    if (pid /= c_getpid() .and. running(pid)) then
      call fatal_error(err, dir//' is in use by another casca run (process '//itoa(pid)// &
                       ', '//dir//lock_name//'); give this run another folder (--out)')
      return
    end if
    call delete_file(dir//lock_name)
    call try_lock(dir, got, err)
    if (allocated(err)) return
    if (.not. got) then
      call fatal_error(err, dir//' was taken by another casca run at the same time ('// &
                       dir//lock_name//')')
      return
    end if
    note = 'took over '//dir//lock_name//' of process '//itoa(pid)// &
           ', which no longer runs (an earlier run ended without removing it)'
  end subroutine lock_folder

  !> Whether process pid exists and is not a zombie
  logical function running(pid)
    integer, intent(in) :: pid
    character(len=512) :: line
    integer :: u, ios, k
    running = c_kill(int(pid, c_int), 0_c_int) == 0
    if (.not. running) return
    open (newunit=u, file='/proc/'//itoa(pid)//'/stat', status='old', action='read', iostat=ios)
    if (ios /= 0) return   ! (no /proc: kill's answer)
    read (u, '(a)', iostat=ios) line
    close (u)
    if (ios /= 0) return
    k = index(line, ')', back=.true.)   ! (the state follows the command's name in brackets)
    if (k > 0 .and. k + 2 <= len(line)) running = .not. (line(k + 2:k + 2) == 'Z' .or. line(k + 2:k + 2) == 'X')
  end function running

  !> Give the lock back (only if this process holds it).
  subroutine unlock_folder(dir)
    character(len=*), intent(in) :: dir
    if (holder(dir) == c_getpid()) call delete_file(dir//lock_name)
  end subroutine unlock_folder

  !> Whether this process holds dir's lock: dir is the folder this run writes, however the
  !> two paths are spelled
  logical function locked_here(dir)
    character(len=*), intent(in) :: dir
    locked_here = holder(dir) == c_getpid()
  end function locked_here

  !> got: the lock file was created and holds this process's id
  subroutine try_lock(dir, got, err)
    character(len=*), intent(in) :: dir
    logical, intent(out) :: got
    type(error_t), allocatable, intent(out) :: err
    integer :: u, ios
    logical :: exists
    character(len=256) :: msg
    got = .false.
    open (newunit=u, file=dir//lock_name, status='new', action='write', iostat=ios, iomsg=msg)
    if (ios /= 0) then
      inquire (file=dir//lock_name, exist=exists)
      if (.not. exists) call fatal_error(err, dir//lock_name//': '//trim(msg))
      return
    end if
    write (u, '(i0)', iostat=ios, iomsg=msg) c_getpid()
    if (ios == 0) close (u, iostat=ios, iomsg=msg)
    if (ios /= 0) then
      close (u, status='delete', iostat=ios)
      call fatal_error(err, dir//lock_name//': cannot write: '//trim(msg))
      return
    end if
    got = .true.
  end subroutine try_lock

  !> process id in dir's lock file (0 if there is none or it is unreadable)
  integer function holder(dir)
    character(len=*), intent(in) :: dir
    integer :: u, ios
    holder = 0
    open (newunit=u, file=dir//lock_name, status='old', action='read', iostat=ios)
    if (ios /= 0) return
    read (u, *, iostat=ios) holder
    if (ios /= 0) holder = 0
    close (u, iostat=ios)
  end function holder
end module casca_output_lock
