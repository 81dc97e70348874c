!> What `casca check` says about each contact pair at t = 0: the smallest gap between the
!> surfaces in contact (faces: mid-surfaces less half of each reference thickness along the
!> fibre, as a constraint measures it: (h/2)|G.u|, none for a shell met edge-on, its fibre
!> more than 60 degrees from the line u, but h/2 all round for a target's rim met by a
!> one-pass pair's node, rounded as projection.f90 rounds it; 'mid': the mid-surfaces) and
!> the time to contact at the bodies' initial velocities.
!>
!> The contact's own probe only sees nodes within the search radius, so the distance here is
!> computed from scratch, for bodies at any distance: every impactor node against every
!> sub-triangle of the target (the chords of its cubic elements, 9 per element), a triangle's
!> bounding box skipping it when it cannot beat the best so far. The answer is exact where
!> the closest point is a target node and overestimates the gap to a convex target's cubic
!> surface by at most the chord's sagitta, kappa e^2 / 8 (e: sub-triangle edge, kappa: the
!> target's curvature). An obstacle's distance is exact (obstacle_point).
!>
!> The time to contact is the smallest gap over the closing speed at that closest approach
!> (the relative velocity along the line between the two points): straight-line motion, no
!> deformation, no gravity. 'never' when that speed is not positive; a body's own surface
!> (self-contact) is never closed by its rigid initial motion.
module casca_pair_gaps
  use casca_kinds, only: dp
  use casca_model, only: model_t, dof
  use casca_obstacle, only: obstacle_point
  use casca_closest_point, only: closest_point_triangle
  use casca_contact, only: contact_t, tested_both_ways
  use casca_contact_projection, only: face, positions, on_rim
  implicit none
  private
  public :: pair_gap_t, pair_gaps, pair_gaps_at, pair_gap_lines

  !> One pair's figures at t = 0
  type :: pair_gap_t
    real(dp) :: gap = huge(1._dp)   !< smallest gap between the surfaces in contact [m]
    real(dp) :: speed = 0           !< closing speed at that closest approach [m/s]
    real(dp) :: time = -1           !< time to contact [s]; < 0: never
    integer :: node = 0             !< the impactor node of the closest approach
  end type pair_gap_t

contains

  !> Gaps and times of every pair of c (made by contact_init) at positions x(3, nnode),
  !> fibres g(3, nnode) and velocities v(3, nnode).
  function pair_gaps(c, model, x, g, v) result(pg)
    type(contact_t), intent(in) :: c
    type(model_t), intent(in) :: model
    real(dp), intent(in) :: x(:, :), g(:, :), v(:, :)
    type(pair_gap_t) :: pg(c%npairs)
    integer :: ip, bi, bt, n, it, k, best_tri, region, best_region
    real(dp) :: nrm(3), d, q(3), bary(3), dist, best, best_bary(3), best_q(3), u(3), vt(3), gap, ft
    logical :: rounded
    real(dp), allocatable :: lo(:, :), hi(:, :)
    logical :: rounded_rim   !< the pair meets its target's rim rounded (one pass)
    do ip = 1, c%npairs
      bi = c%pair(1, ip); bt = c%pair(2, ip)
      associate (r => pg(ip), bd => model%body(bi))
        if (bt <= 0) then   ! an obstacle, where it is at t = 0
          associate (ob => c%obstacle(-bt))
            do n = bd%node_first, bd%node_last
              ! (a node held in place is never constrained: active_set.f90)
              if (all(model%fixed(dof(n, 1):dof(n, 3)))) cycle
              call obstacle_point(ob, 0._dp, x(:, n), nrm, d)
              gap = d - face_along(c, model, bi, g(:, n), nrm)
              if (gap < r%gap) then
                r%gap = gap; r%node = n
                r%speed = -dot_product(v(:, n) - ob%velocity, nrm)
              end if
            end do
          end associate
        else
          rounded_rim = bi /= bt .and. .not. tested_both_ways(c, bi, bt)
          associate (s => c%geo%surf(bt))
            allocate (lo(3, s%ntri), hi(3, s%ntri))
            do it = 1, s%ntri
              lo(:, it) = minval(x(:, s%tri(:, it)), dim=2)
              hi(:, it) = maxval(x(:, s%tri(:, it)), dim=2)
            end do
            do n = bd%node_first, bd%node_last
              best = huge(1._dp); best_tri = 0
              do it = 1, s%ntri
                ! the box's distance is a lower bound of the triangle's
                if (norm2(max(lo(:, it) - x(:, n), 0._dp, x(:, n) - hi(:, it))) >= best) cycle
                ! self-contact: not the surface around the node (as the contact leaves it out)
                if (bi == bt) then
                  if (any([(norm2(model%x0(:, s%tri(k, it)) - model%x0(:, n)) < c%geo%skip(bt), &
                            k=1, 3)])) cycle
                end if
                call closest_point_triangle(x(:, n), x(:, s%tri(1, it)), x(:, s%tri(2, it)), &
                                            x(:, s%tri(3, it)), q, bary, region)
                dist = norm2(x(:, n) - q)
                if (dist < best) then
                  best = dist; best_tri = it; best_bary = bary; best_q = q; best_region = region
                end if
              end do
              if (best_tri == 0) cycle
              u = x(:, n) - best_q
              if (norm2(u) > 0) u = u/norm2(u)
              rounded = c%faces .and. rounded_rim .and. on_rim(s, best_tri, best_region)
              if (rounded) then
                ft = 0.5_dp*model%body(bt)%thickness
              else
                ft = face_along(c, model, bt, matmul(g(:, s%tri(:, best_tri)), best_bary), u)
              end if
              gap = best - face_along(c, model, bi, g(:, n), u) - ft
              if (gap >= r%gap) cycle
              r%gap = gap; r%node = n
              vt = matmul(v(:, s%tri(:, best_tri)), best_bary)
              r%speed = -dot_product(v(:, n) - vt, u)
            end do
            deallocate (lo, hi)
          end associate
        end if
        ! closing: faster than rounding of the bodies' speeds (a rigid body's own surface
        ! gives 0 to rounding)
        if (r%node > 0 .and. bi /= bt .and. r%speed > 1e-12_dp*max_speed(c, model, v, bi, bt)) &
          r%time = max(r%gap, 0._dp)/r%speed
        r%speed = r%speed + 0._dp   ! (no -0 printed)
      end associate
    end do
  end function pair_gaps

  !> pair_gaps at the parameters q and their rates qd (ndof): positions, fibres, velocities
  function pair_gaps_at(c, model, q, qd) result(pg)
    type(contact_t), intent(in) :: c
    type(model_t), intent(in) :: model
    real(dp), intent(in) :: q(:), qd(:)
    type(pair_gap_t) :: pg(c%npairs)
    pg = pair_gaps(c, model, positions(model, q), positions(model, q, fibres=.true.), positions(model, qd))
  end function pair_gaps_at

  !> body b's face along u, as a new constraint chooses it (projection.f90); none between
  !> mid-surfaces. (Module procedures, not internal ones: gfortran gave the binary an
  !> executable stack for them.)
  real(dp) function face_along(c, model, b, gf, u)
    type(contact_t), intent(in) :: c
    type(model_t), intent(in) :: model
    integer, intent(in) :: b
    real(dp), intent(in) :: gf(3), u(3)
    integer :: s
    real(dp) :: w
    face_along = 0
    if (.not. c%faces) return
    s = 0
    call face(model%body(b)%thickness, gf, u, s, face_along, w)
  end function face_along

  !> the fastest node of bodies b1 and b2 (or obstacle -b2)
  real(dp) function max_speed(c, model, v, b1, b2)
    type(contact_t), intent(in) :: c
    type(model_t), intent(in) :: model
    real(dp), intent(in) :: v(:, :)
    integer, intent(in) :: b1, b2
    integer :: m
    max_speed = tiny(1._dp)
    do m = model%body(b1)%node_first, model%body(b1)%node_last
      max_speed = max(max_speed, norm2(v(:, m)))
    end do
    if (b2 <= 0) then
      max_speed = max(max_speed, norm2(c%obstacle(-b2)%velocity))
      return
    end if
    do m = model%body(b2)%node_first, model%body(b2)%node_last
      max_speed = max(max_speed, norm2(v(:, m)))
    end do
  end function max_speed

  !> One line per pair: names(t) is target t's name (bodies t > 0, obstacles t = -k), then a
  !> line saying how the gap was measured.
  function pair_gap_lines(c, pg, body_names, obstacle_names) result(lines)
    type(contact_t), intent(in) :: c
    type(pair_gap_t), intent(in) :: pg(:)
    character(len=*), intent(in) :: body_names(:), obstacle_names(:)
    character(len=320), allocatable :: lines(:)
    character(len=:), allocatable :: tname, kind
    character(len=40) :: when
    character(len=10) :: skip
    integer :: ip, bi, bt
    allocate (lines(size(pg) + 1))
    do ip = 1, size(pg)
      bi = c%pair(1, ip); bt = c%pair(2, ip)
      if (bt > 0) then
        tname = trim(body_names(bt)); kind = ''
        if (bt == bi) then   ! (what a fold closer than this cannot touch: say it)
          write (skip, '(es10.3)') c%geo%skip(bt)
          kind = ' (self-contact; the surface within '//trim(adjustl(skip))// &
                 ' m of a node at the start is not tested against it)'
        end if
      else
        tname = trim(obstacle_names(-bt)); kind = ' (obstacle)'
      end if
      if (pg(ip)%node == 0) then
        write (lines(ip), '(6a)') 'pair ''', trim(body_names(bi)), ''' -> ''', tname, ''''//kind, &
          ': no node to measure (every node held, or nothing beyond its own neighbourhood)'
        cycle
      end if
      when = 'never'
      if (pg(ip)%time >= 0) write (when, '(es14.7,a)') pg(ip)%time, ' s'
      write (lines(ip), '(6a,es14.7,a,es14.7,2a)') 'pair ''', trim(body_names(bi)), ''' -> ''', &
        tname, ''''//kind, ': gap ', pg(ip)%gap, ' m, closing speed ', pg(ip)%speed, &
        ' m/s, time to contact ', trim(adjustl(when))
    end do
    if (c%faces) then
      lines(size(pg) + 1) = '(gaps between the shell faces, half of each thickness from the '// &
        'mid-surfaces; to the target''s sub-triangles: exact at its nodes, chords between them; '// &
        'times at the initial velocities, without deformation or gravity)'
    else
      lines(size(pg) + 1) = '(gaps between the mid-surfaces; to the target''s sub-triangles: '// &
        'exact at its nodes, chords between them; times at the initial velocities, without '// &
        'deformation or gravity)'
    end if
  end function pair_gap_lines
end module casca_pair_gaps
