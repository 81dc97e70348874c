!> The loads that depend on the state, in Newton's residual and tangent and in the energy
!> accounting: the follower pressure of the model's loaded elements (model%pressure) and the
!> moments on nodes' fibres (model%moment). The elements are split over the ranks as
!> casca_assembly splits them: the pressure's force is summed over the ranks and each rank
!> adds the load stiffness to its own elements' matrix entries; a moment's stiffness goes
!> into its node's block of one element (model%moment_elem).
module casca_follower_loads
  use casca_kinds, only: dp
  use casca_model, only: model_t, dof
  use casca_assembly, only: assembly_t
  use casca_shell_element, only: ndof_elem, ndof_node
  use casca_pressure_load, only: pressure_force, pressure_volume
  use casca_moment_load, only: moment_force, moment_turn
  use casca_mpi, only: sum_all, is_root
  implicit none
  private
  public :: add_follower_loads, pressure_work_local, follower_path_local

contains

  !> r -= factor (f_p(q) + f_m(q)) and, with want_k, asm%a -= factor (sym(K_p) + K_m): the
  !> moments' (add_moments) and the pressure's. The pressure is an
  !> external load at the current iterate, r = f_int - f_ext. The element load stiffness K_p
  !> is unsymmetric, but over a closed surface (or one whose boundary is held) the assembled
  !> one is symmetric: the element's skew part is a boundary integral that cancels between
  !> neighbours (exactly on flat elements; to the area rule's accuracy on curved ones, where
  !> the rule does not integrate it exactly). casca's matrices are symmetric (MUMPS takes the lower triangle), so the
  !> element's symmetric part is added. scale: the largest entry of factor f_p on the free
  !> parameters, the loads' share of the scene's force scale (0 without them).
  !> The elements are those assemble used for the same want_k (collective: every rank calls).
  !> Without model%load_stiffness the tangent is left as it is (to show what it is worth).
  subroutine add_follower_loads(model, asm, q, want_k, r, scale, factor, qn, af)
    type(model_t), intent(in) :: model
    type(assembly_t), intent(inout) :: asm
    real(dp), intent(in) :: q(:)
    logical, intent(in) :: want_k
    real(dp), intent(inout) :: r(:)
    real(dp), intent(out) :: scale
    real(dp), intent(in), optional :: factor   !< load factor (statics); default 1
    real(dp), intent(in), optional :: qn(:), af   !< generalized-alpha: at (1-af) q + af qn,
                                                  !< as the internal force (casca_assembly)
    real(dp), allocatable :: fp(:), qa(:)
    real(dp) :: w
    integer, allocatable :: elems(:)   !< assemble's for want_k: the tangent's, else dealt round
    real(dp) :: lf, y(3, 10), f(3, 10), k(3, 10, 3, 10)
    integer :: i, e, l, p, row, col, ca, cb
    logical :: stiff

    scale = 0
    if (all(model%pressure == 0) .and. all(model%moment == 0)) return
    lf = 1
    if (present(factor)) lf = factor
    stiff = want_k .and. model%load_stiffness
    w = 0
    if (present(af) .and. present(qn)) w = af
    qa = (1 - w)*q
    if (w /= 0) qa = qa + w*qn
    allocate (fp(model%ndof))
    fp = 0
    if (any(model%moment /= 0)) call add_moments(model, asm, qa, stiff, lf, 1 - w, fp)
    if (want_k) then
      elems = asm%elems
    else
      elems = asm%dealt
    end if
    do i = 1, size(elems)
      e = elems(i)
      if (model%pressure(e) == 0) cycle
      call element_positions(model, qa, e, y)
      call pressure_force(model%rule, lf*model%pressure(e), y, stiff, f, k)
      do l = 1, 10
        associate (n => model%conn(l, e))
          fp(dof(n, 1):dof(n, 3)) = fp(dof(n, 1):dof(n, 3)) + f(:, l)
        end associate
      end do
      if (.not. stiff) cycle
      do p = asm%estart(i), asm%estart(i + 1) - 1
        row = mod(asm%pos(p) - 1, ndof_elem); col = (asm%pos(p) - 1)/ndof_elem   ! (from 0)
        ca = mod(row, ndof_node) + 1; cb = mod(col, ndof_node) + 1
        if (ca > 3 .or. cb > 3) cycle   ! (only positions carry it)
        asm%a(p) = asm%a(p) - 0.5_dp*(1 - w)*(k(ca, row/ndof_node + 1, cb, col/ndof_node + 1) + &
                                              k(cb, col/ndof_node + 1, ca, row/ndof_node + 1))
      end do
    end do
    call sum_all(fp)
    r = r - fp
    scale = maxval(abs(fp), mask=.not. model%fixed, dim=1)
    scale = max(scale, 0._dp)   ! (every parameter fixed: maxval of nothing)
  end subroutine add_follower_loads

  !> The moments' loads on the fibres at qa, factor lf, into fp, this rank's share (the root's:
  !> fp is summed over the ranks); with stiff, -lf wk K_m into the entries of each node's
  !> fibre block in its moment_elem, where this rank assembles that element (wk: the share of
  !> the end state in qa, 1 - alpha_f)
  subroutine add_moments(model, asm, qa, stiff, lf, wk, fp)
    type(model_t), intent(in) :: model
    type(assembly_t), intent(inout) :: asm
    real(dp), intent(in) :: qa(:), lf, wk
    logical, intent(in) :: stiff
    real(dp), intent(inout) :: fp(:)
    real(dp) :: f(3), k(3, 3)
    integer :: i, e, n, p, row, col, l, nk
    if (is_root()) then
      do n = 1, model%nnode
        if (all(model%moment(:, n) == 0)) cycle
        call moment_force(lf*model%moment(:, n), qa(dof(n, 4):dof(n, 6)), f, k)
        fp(dof(n, 4):dof(n, 6)) = fp(dof(n, 4):dof(n, 6)) + f
      end do
    end if
    if (.not. stiff) return
    nk = 0   ! (the node whose k is at hand: its block's entries follow each other)
    do i = 1, size(asm%elems)
      e = asm%elems(i)
      if (all(model%moment_elem(model%conn(:, e)) /= e)) cycle
      do p = asm%estart(i), asm%estart(i + 1) - 1
        row = mod(asm%pos(p) - 1, ndof_elem); col = (asm%pos(p) - 1)/ndof_elem   ! (from 0)
        l = row/ndof_node + 1
        if (col/ndof_node + 1 /= l) cycle   ! (a node's own block only)
        if (mod(row, ndof_node) < 3 .or. mod(row, ndof_node) > 5 .or. &
            mod(col, ndof_node) < 3 .or. mod(col, ndof_node) > 5) cycle   ! (its fibre's)
        n = model%conn(l, e)
        if (model%moment_elem(n) /= e .or. all(model%moment(:, n) == 0)) cycle
        if (n /= nk) call moment_force(lf*model%moment(:, n), qa(dof(n, 4):dof(n, 6)), f, k)
        nk = n
        asm%a(p) = asm%a(p) - wk*k(mod(row, ndof_node) - 2, mod(col, ndof_node) - 2)
      end do
    end do
  end subroutine add_moments

  !> This rank's share of the pressures' work at q from q0 on the closed surfaces
  !> (model%pressure_closed), factor sum p (V(q) - V(q0)) over elems (pressure_volume): exact
  !> there, a function of the state; not summed over the ranks. The open surfaces' is
  !> follower_path_local's.
  real(dp) function pressure_work_local(model, elems, q, q0, factor) result(w)
    type(model_t), intent(in) :: model
    integer, intent(in) :: elems(:)
    real(dp), intent(in) :: q(:), q0(:), factor
    real(dp) :: y(3, 10), y0(3, 10)
    integer :: i, e
    w = 0
    do i = 1, size(elems)
      e = elems(i)
      if (model%pressure(e) == 0 .or. .not. model%pressure_closed(e)) cycle
      call element_positions(model, q, e, y)
      call element_positions(model, q0, e, y0)
      w = w + model%pressure(e)*(pressure_volume(model%rule, y) - pressure_volume(model%rule, y0))
    end do
    w = factor*w
  end function pressure_work_local

  !> This rank's share of the work at load factor 1 from qa to qb of the pressures on the open
  !> surfaces (those not model%pressure_closed), along the straight path by Simpson's rule
  !> (f_p is quadratic in the positions, so the rule is exact on the segment), and the root's
  !> of the moments, |m| times the fibre's turn (exact for a turn below pi). On an open
  !> surface the follower pressure has no potential (p (V - V0) there depends on the
  !> origin), and a moment's angle is known only modulo 2 pi, so their work is this sum over
  !> the steps; not summed over the ranks.
  real(dp) function follower_path_local(model, elems, qa, qb) result(w)
    type(model_t), intent(in) :: model
    integer, intent(in) :: elems(:)
    real(dp), intent(in) :: qa(:), qb(:)
    real(dp) :: ya(3, 10), yb(3, 10), fa(3, 10), fm(3, 10), fb(3, 10), k(3, 10, 3, 10)
    integer :: i, e, n
    w = 0
    if (is_root()) then
      do n = 1, model%nnode
        if (any(model%moment(:, n) /= 0)) w = w + norm2(model%moment(:, n))* &
          moment_turn(model%moment(:, n), qa(dof(n, 4):dof(n, 6)), qb(dof(n, 4):dof(n, 6)))
      end do
    end if
    do i = 1, size(elems)
      e = elems(i)
      if (model%pressure(e) == 0 .or. model%pressure_closed(e)) cycle
      call element_positions(model, qa, e, ya)
      call element_positions(model, qb, e, yb)
      call pressure_force(model%rule, model%pressure(e), ya, .false., fa, k)
      call pressure_force(model%rule, model%pressure(e), (ya + yb)/2, .false., fm, k)
      call pressure_force(model%rule, model%pressure(e), yb, .false., fb, k)
      w = w + sum((yb - ya)*(fa + 4*fm + fb))/6
    end do
  end function follower_path_local

  !> the positions Y of element e's 10 nodes from a full-length vector
  pure subroutine element_positions(model, q, e, y)
    type(model_t), intent(in) :: model
    real(dp), intent(in) :: q(:)
    integer, intent(in) :: e
    real(dp), intent(out) :: y(3, 10)
    integer :: l
    do l = 1, 10
      y(:, l) = q(dof(model%conn(l, e), 1):dof(model%conn(l, e), 3))
    end do
  end subroutine element_positions
end module casca_follower_loads
