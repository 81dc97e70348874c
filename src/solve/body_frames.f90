!> Kept factors on turning bodies. A body's tangent turns with it: for a rigid rotation R of
!> its nodes' vector parameters, K(R q) = Q K(q) Q^T with Q = R on each Y and G triplet and 1 on
!> the thickness parameter A (the strain energy, the inertia M (x) I3 and the follower
!> pressures are all frame-indifferent). Factors made when the body stood at q_f therefore
!> serve at q as Q K_f^-1 Q^T, R the best-fit rotation of its nodes from q_f to q. Without it
!> a ball spinning at 30 rad/s needed new factors every third or fourth step: kept factors
!> contract only while the body has turned by a few milliradians since they were made.
!> Only bodies with no prescribed parameter turn (a held body does not rotate rigidly).
module casca_body_frames
  use casca_kinds, only: dp
  use casca_model, only: model_t, dof
  use casca_lapack, only: dsyev
  implicit none
  private
  public :: body_frames_t, frames_keep, frames_follow, frames_turn

  !> a rotation in use is renewed when the body has turned by more than this [rad] since
  !> (each renewal costs the Schur path its columns of Z)
  real(dp), parameter :: renew_angle = 1e-3_dp

  type :: body_frames_t
    real(dp), allocatable :: y(:, :)       !< (3, nnode) mid-surface when K was factorised
    real(dp), allocatable :: rot(:, :, :)  !< (3, 3, nbody) rotation in use, q_f to q
    logical, allocatable :: free(:)        !< (nbody) no prescribed parameter
    integer, allocatable :: trip(:, :)     !< (3, k) equations of a Y or G triplet of a free body
    integer, allocatable :: trip_body(:)   !< (k) its body
    logical :: turned = .false.            !< some rotation in use is not the identity
  end type body_frames_t

contains

  !> K was factorised at q: its frame is the bodies' present one. eq: equation of each dof on
  !> this rank (0: not here), listed anew each time (bodies frozen or woken change it).
  subroutine frames_keep(f, model, eq, q)
    type(body_frames_t), intent(inout) :: f
    type(model_t), intent(in) :: model
    integer, intent(in) :: eq(:)
    real(dp), intent(in) :: q(:)
    integer :: b, n, c, k, pass
    if (.not. allocated(f%free)) then
      allocate (f%free(model%nbody), f%rot(3, 3, model%nbody), f%y(3, model%nnode))
      do b = 1, model%nbody
        associate (bd => model%body(b))
          f%free(b) = .not. any(model%fixed(dof(bd%node_first, 1):dof(bd%node_last, 7)))
        end associate
      end do
    end if
    if (allocated(f%trip)) deallocate (f%trip, f%trip_body)
    do pass = 1, 2   ! the triplets of this rank's equations, counted then listed
      k = 0
      do b = 1, model%nbody
        if (.not. f%free(b)) cycle
        do n = model%body(b)%node_first, model%body(b)%node_last
          do c = 1, 4, 3
            if (any(eq(dof(n, c):dof(n, c + 2)) == 0)) cycle
            k = k + 1
            if (pass == 2) then
              f%trip(:, k) = eq(dof(n, c):dof(n, c + 2)); f%trip_body(k) = b
            end if
          end do
        end do
      end do
      if (pass == 1) allocate (f%trip(3, k), f%trip_body(k))
    end do
    do n = 1, model%nnode
      f%y(:, n) = q(dof(n, 1):dof(n, 3))
    end do
    f%rot = 0
    do c = 1, 3
      f%rot(c, c, :) = 1
    end do
    f%turned = .false.
  end subroutine frames_keep

  !> The free bodies' rotations from the frame kept to q, renewed where one has turned by more
  !> than renew_angle since the one in use. True when a rotation in use changed (q is the same
  !> on every rank, so the answer is too).
  logical function frames_follow(f, model, q) result(changed)
    type(body_frames_t), intent(inout) :: f
    type(model_t), intent(in) :: model
    real(dp), intent(in) :: q(:)
    real(dp) :: r(3, 3)
    integer :: b
    changed = .false.
    if (.not. allocated(f%free)) return
    do b = 1, model%nbody
      if (.not. f%free(b)) cycle
      r = best_rotation(f%y(:, model%body(b)%node_first:model%body(b)%node_last), &
                        q(dof(model%body(b)%node_first, 1):dof(model%body(b)%node_last, 7)))
      if (norm2(r - f%rot(:, :, b)) > sqrt(2._dp)*renew_angle) then
        f%rot(:, :, b) = r
        changed = .true.
        f%turned = .true.
      end if
    end do
  end function frames_follow

  !> x(eq, :) = Q^T x (back: into the frame of the factors) or Q x, triplet by triplet
  subroutine frames_turn(f, x, back)
    type(body_frames_t), intent(in) :: f
    real(dp), intent(inout) :: x(:, :)
    logical, intent(in) :: back
    real(dp) :: r(3, 3)
    integer :: k, j
    if (.not. f%turned) return
    do k = 1, size(f%trip_body)
      r = f%rot(:, :, f%trip_body(k))
      if (back) r = transpose(r)
      do j = 1, size(x, 2)
        x(f%trip(:, k), j) = matmul(r, x(f%trip(:, k), j))
      end do
    end do
  end subroutine frames_turn

  !> The rotation R that best carries the points y0 onto the mid-surface of qb (the body's
  !> parameters, 7 a node) about their centroids, from the largest eigenvector of Horn's
  !> (1987) 4 x 4 matrix, the unit quaternion of R
  function best_rotation(y0, qb) result(r)
    real(dp), intent(in) :: y0(:, :), qb(:)
    real(dp) :: r(3, 3)
    real(dp) :: c0(3), c1(3), s(3, 3), nm(4, 4), ev(4), work(64), u(4), x(3), y(3)
    integer :: n, a, info
    c0 = 0; c1 = 0
    do n = 1, size(y0, 2)
      c0 = c0 + y0(:, n); c1 = c1 + qb(7*n - 6:7*n - 4)
    end do
    c0 = c0/size(y0, 2); c1 = c1/size(y0, 2)
    s = 0
    do n = 1, size(y0, 2)
      x = y0(:, n) - c0; y = qb(7*n - 6:7*n - 4) - c1
      do a = 1, 3   ! s(a, b) = sum x_a y_b
        s(a, :) = s(a, :) + x(a)*y
      end do
    end do
    nm(1, :) = [s(1, 1) + s(2, 2) + s(3, 3), s(2, 3) - s(3, 2), s(3, 1) - s(1, 3), s(1, 2) - s(2, 1)]
    nm(2, :) = [s(2, 3) - s(3, 2), s(1, 1) - s(2, 2) - s(3, 3), s(1, 2) + s(2, 1), s(3, 1) + s(1, 3)]
    nm(3, :) = [s(3, 1) - s(1, 3), s(1, 2) + s(2, 1), -s(1, 1) + s(2, 2) - s(3, 3), s(2, 3) + s(3, 2)]
    nm(4, :) = [s(1, 2) - s(2, 1), s(3, 1) + s(1, 3), s(2, 3) + s(3, 2), -s(1, 1) - s(2, 2) + s(3, 3)]
    call dsyev('V', 'U', 4, nm, 4, ev, work, size(work), info)
    u = nm(:, 4)   ! (eigenvalues ascending)
    if (info /= 0) u = [1._dp, 0._dp, 0._dp, 0._dp]
    r(1, :) = [u(1)**2 + u(2)**2 - u(3)**2 - u(4)**2, 2*(u(2)*u(3) - u(1)*u(4)), &
               2*(u(2)*u(4) + u(1)*u(3))]
    r(2, :) = [2*(u(3)*u(2) + u(1)*u(4)), u(1)**2 - u(2)**2 + u(3)**2 - u(4)**2, &
               2*(u(3)*u(4) - u(1)*u(2))]
    r(3, :) = [2*(u(4)*u(2) - u(1)*u(3)), 2*(u(4)*u(3) + u(1)*u(2)), &
               u(1)**2 - u(2)**2 - u(3)**2 + u(4)**2]
  end function best_rotation
end module casca_body_frames
