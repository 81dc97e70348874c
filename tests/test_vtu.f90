!> Writes a small VTU/PVD pair for tests/test_vtu.py to check with meshio (and VTK if present).
!>
!> Usage: test_vtu OUTDIR
!>   OUTDIR/cyl_0000.vtu, OUTDIR/cyl_0001.vtu: two frames of the same two-element mesh
!>   OUTDIR/cyl.pvd: collection of both (rewritten after each frame)
!>
!> Element 1 is curved: the image of the reference triangle under (xi1,xi2) -> (theta, z) =
!> (0.6 xi1, 0.4 xi2) on the unit cylinder, nodes exactly on it. Element 2 is flat (affine).
!> Global node numbers are scrambled so that conn is not the identity. The field values use
!> only correctly rounded +-*/ so Python can recompute them bit for bit:
!>   node k (global number): displacement = s*(k/3, -1/(k+7), k*1e-3), thickness_param = 0.5+k/100
!>   with s = 1 in frame 0 and s = 2 in frame 1; cell e: body = e.
!> The program also checks that bad input comes back as an error, not a crash.
program test_vtu
  use casca_kinds, only: dp
  use casca_error, only: error_t
  use casca_vtu_writer, only: field_t, field, write_vtu, write_pvd
  implicit none

  integer, parameter :: nen = 10, nelem = 2, nnode = nen*nelem
  ! Reference coordinates of the 10 nodes in casca (= VTK Lagrange) order.
  real(dp), parameter :: xi_ref(2, nen) = reshape([ &
                                                  0.0_dp, 0.0_dp, 1.0_dp, 0.0_dp, 0.0_dp, 1.0_dp, &
                                                  1.0_dp/3, 0.0_dp, 2.0_dp/3, 0.0_dp, &
                                                  2.0_dp/3, 1.0_dp/3, 1.0_dp/3, 2.0_dp/3, &
                                                  0.0_dp, 2.0_dp/3, 0.0_dp, 1.0_dp/3, &
                                                  1.0_dp/3, 1.0_dp/3], [2, nen])
  ! Flat element: X = p0 + xi1*(p1-p0) + xi2*(p2-p0).
  real(dp), parameter :: p0(3) = [2.0_dp, 0.0_dp, 0.0_dp], p1(3) = [3.0_dp, 0.0_dp, 0.0_dp], &
                         p2(3) = [2.0_dp, 1.0_dp, 0.5_dp]
  ! Global number of (local node a, element e): a fixed scramble of 1..20.
  integer, parameter :: perm(nnode) = [7, 13, 2, 19, 11, 5, 16, 1, 20, 9, &
                                       4, 14, 18, 3, 10, 17, 6, 12, 15, 8]

  real(dp) :: x(3, nnode), disp(3, nnode), thick(1, nnode), body(1, nelem), theta, times(2)
  integer :: conn(nen, nelem), a, e, k, iframe, nfail
  character(len=:), allocatable :: outdir
  character(len=16) :: files(2)
  type(error_t), allocatable :: err
  type(field_t), allocatable :: pf(:), cf(:), none(:)

  call get_outdir(outdir)
  nfail = 0

  do e = 1, nelem
    do a = 1, nen
      conn(a, e) = perm(a + nen*(e - 1))
      k = conn(a, e)
      if (e == 1) then
        theta = 0.6_dp*xi_ref(1, a)
        x(:, k) = [cos(theta), sin(theta), 0.4_dp*xi_ref(2, a)]
      else
        x(:, k) = p0 + xi_ref(1, a)*(p1 - p0) + xi_ref(2, a)*(p2 - p0)
      end if
    end do
  end do
  do k = 1, nnode
    disp(:, k) = [real(k, dp)/3, -1.0_dp/real(k + 7, dp), real(k, dp)*1.0e-3_dp]
    thick(1, k) = 0.5_dp + real(k, dp)/100
  end do
  body(1, :) = [(real(e, dp), e=1, nelem)]

  files = ['cyl_0000.vtu', 'cyl_0001.vtu']
  times = [0.0_dp, 1.5e-3_dp]
  cf = [field('body', body)]
  do iframe = 1, 2
    pf = [field('displacement', real(iframe, dp)*disp), field('thickness_param', thick)]
    call write_vtu(outdir//'/'//trim(files(iframe)), x, conn, pf, cf, err)
    call expect_ok('write_vtu frame '//achar(iachar('0') + iframe - 1))
    ! The collection is rewritten after every frame so it is always valid.
    call write_pvd(outdir//'/cyl.pvd', files(1:iframe), times(1:iframe), err)
    call expect_ok('write_pvd after frame '//achar(iachar('0') + iframe - 1))
  end do

  ! Errors must come back in err (and leave no file behind), never stop the program.
  allocate (none(0))
  call write_vtu(outdir//'/no_such_dir/bad.vtu', x, conn, none, none, err)
  call expect_error('write_vtu into a missing folder')
  call write_vtu(outdir//'/bad_conn.vtu', x, conn + nnode, none, none, err)
  call expect_error('write_vtu with node number out of range')
  call write_vtu(outdir//'/bad_field.vtu', x, conn, [field('short', thick(:, 1:3))], none, err)
  call expect_error('write_vtu with wrong field length')
  call write_pvd(outdir//'/bad.pvd', files, times(1:1), err)
  call expect_error('write_pvd with mismatched sizes')

  ! An element-free mesh with no fields is still a valid file.
  call write_vtu(outdir//'/empty.vtu', x(:, 1:0), conn(:, 1:0), none, none, err)
  call expect_ok('write_vtu with no cells')

  if (nfail > 0) then
    write (*, '(a,i0,a)') 'test_vtu: ', nfail, ' check(s) failed'
    error stop 1
  end if
  write (*, '(a)') 'test_vtu: wrote '//outdir//'/cyl.pvd'

contains

  subroutine get_outdir(dir)
    character(len=:), allocatable, intent(out) :: dir
    integer :: n, stat
    call get_command_argument(1, length=n, status=stat)
    if (stat /= 0 .or. n == 0) then
      write (*, '(a)') 'usage: test_vtu OUTDIR'
      error stop 2
    end if
    allocate (character(len=n) :: dir)
    call get_command_argument(1, dir)
  end subroutine get_outdir

  subroutine expect_ok(what)
    character(len=*), intent(in) :: what
    if (allocated(err)) then
      write (*, '(a)') 'FAIL '//what//': '//err%message
      nfail = nfail + 1
    end if
  end subroutine expect_ok

  subroutine expect_error(what)
    character(len=*), intent(in) :: what
    if (.not. allocated(err)) then
      write (*, '(a)') 'FAIL '//what//': no error reported'
      nfail = nfail + 1
    else
      write (*, '(a)') 'ok   '//what//' -> '//err%message
    end if
  end subroutine expect_error
end program test_vtu
