!> Element loop over this rank's elements: internal (and inertial) force into a full-length
!> residual summed over the ranks, and the tangent into this rank's part of MUMPS's
!> distributed input. The entry pattern is fixed at setup: each element writes its lower
!> triangle of free-parameter pairs, in the same order at every call.
!>
!> Without constraints in the matrix K is block diagonal by body, so the bodies with unknowns
!> are dealt to groups of ranks (as many as bodies, up to one rank each) and each group
!> factorises and solves its own block: the solves, which dominate a long run, then need no
!> communication at all. Two equal bodies on two ranks solve twice as fast, where one MUMPS
!> instance over both ranks solves 1.5x as fast. Bodies left over when they do not deal evenly
!> (one of three spheres on two ranks) form a second block shared by all ranks, with a
!> MUMPS instance of its own; bodies that share out neither way stay in one instance
!> (docs/performance.md).
module casca_assembly
  use casca_kinds, only: dp
  use casca_error, only: error_t, fatal_error
  use casca_model, only: model_t, element_dofs, element_energy
  use casca_shell_element, only: shell_energy_force, ndof_elem
  use casca_mpi, only: my_rank, n_ranks, sum_all, bcast_int, is_root
  use casca_metis, only: partition_elements
  implicit none
  private
  public :: assembly_t, block_t, assembly_setup, assemble, strain_energy, strain_energy_local, &
            nblocks

  integer, parameter :: nblocks = 2   !< 1: this rank's group's bodies; 2: the shared bodies

  !> A diagonal block of K factorised by one MUMPS instance: its equations are off+1..off+neq
  !> of this rank's numbering, its entries first..last of irn, jcn, a (numbered within the block)
  type :: block_t
    integer :: neq = 0, off = 0
    integer :: first = 1, last = 0
    integer :: ngroups = 1   !< its ranks: casca_mpi's group_handle(ngroups) (1: all ranks)
    logical :: host = .true. !< this rank is the block's first (holds b and x)
  end type block_t

  type :: assembly_t
    integer :: neq = 0                     !< equations of this rank's blocks
    integer :: neq_total = 0               !< equations of all blocks
    integer :: ngroups = 1                 !< groups of ranks, each with its bodies' block of K
    type(block_t) :: blk(nblocks)
    integer, allocatable :: group(:)       !< (nbody) group of each body's ranks: rank r is in
                                           !< group mod(r, ngroups); -1 all ranks (block 2)
    integer, allocatable :: eq(:)          !< (ndof) equation in this rank's blocks, else 0
    integer, allocatable :: elems(:)       !< this rank's elements of its blocks (the tangent),
                                           !< block 1's first
    integer, allocatable :: owned(:)       !< this rank's elements for accounting (all bodies)
    integer, allocatable :: dealt(:)       !< elements with unknowns dealt round all ranks:
                                           !< force-only assembly and strain energy, balanced
                                           !< whatever the groups
    integer, allocatable :: estart(:)      !< (size(elems)+1) first entry of each element
    integer, allocatable :: pos(:)         !< element-matrix linear index of each entry
    integer, allocatable :: irn(:), jcn(:) !< block equations of each entry (irn >= jcn)
    real(dp), allocatable :: a(:)          !< values
  end type assembly_t

contains

  !> The free parameters (neither prescribed nor frozen), the blocks (split: bodies may be
  !> dealt to groups; false when constraints couple the bodies inside the matrix), this
  !> rank's equation numbering, and the elements: those of a block with several ranks are
  !> partitioned by METIS (on rank 0, broadcast so that every rank agrees); the others are
  !> dealt round for the accounting.
  subroutine assembly_setup(model, asm, err, frozen, split)
    type(model_t), intent(in) :: model
    type(assembly_t), intent(out) :: asm
    type(error_t), allocatable, intent(out) :: err
    logical, intent(in), optional :: frozen(:)   !< parameters advanced without solving
    logical, intent(in), optional :: split
    integer :: d(ndof_elem), e, k, i, j, n, ia, ib, g, mine, ng, s, nb, off
    integer, allocatable :: owner(:), active(:), part(:), nfree(:), group(:), bgroup(:)
    logical, allocatable :: free(:)
    real(dp), allocatable :: load(:)

    allocate (free(model%ndof))
    free = .not. model%fixed
    if (present(frozen)) free = free .and. .not. frozen
    asm%neq_total = count(free)
    allocate (nfree(model%nbody), group(model%nbody))
    do i = 1, model%nbody
      nfree(i) = count(free(7*model%body(i)%node_first - 6:7*model%body(i)%node_last))
    end do
    ! groups: as many as bodies (at most one per rank); if the bodies do not deal evenly,
    ! the leftover ones (fewer than the groups) shared by all ranks; else one instance
    asm%ngroups = 1
    group = 0
    if (present(split)) then
      if (split) then
        nb = count(nfree > 0)
        groups: do ng = min(n_ranks, nb), 2, -1
          do s = 0, mod(nb, ng), max(1, mod(nb, ng))
            call deal(ng, s)
            if (maxval(load) <= 1.1_dp*real(sum(nfree), dp)/n_ranks) then
              asm%ngroups = ng
              exit groups
            end if
          end do
        end do groups
        if (asm%ngroups == 1) group = 0
      end if
    end if
    mine = mod(my_rank, asm%ngroups)
    asm%group = group

    ! this rank's numbering: block 1 (its group's bodies), then block 2 (shared bodies)
    allocate (asm%eq(model%ndof))
    asm%eq = 0
    n = 0
    do s = 1, nblocks
      asm%blk(s)%off = n
      g = merge(mine, -1, s == 1)
      do i = 1, model%ndof
        if (.not. free(i) .or. group(model%node_body((i - 1)/7 + 1)) /= g) cycle
        n = n + 1; asm%eq(i) = n
      end do
      asm%blk(s)%neq = n - asm%blk(s)%off
    end do
    asm%neq = n
    asm%blk(1)%ngroups = asm%ngroups
    asm%blk(1)%host = my_rank < asm%ngroups
    asm%blk(2)%host = is_root()

    ! elements with unknowns: owner = a rank of their block, partitioned when it has several
    allocate (owner(model%nelem))
    active = pack([(e, e=1, model%nelem)], [(any(free(element_dofs(model, e))), e=1, model%nelem)])
    bgroup = group(model%elem_body(active))
    owner = [(mod(e, n_ranks), e=1, model%nelem)]
    if (size(active) > 0) then
      allocate (part(size(active)))
      part = 0
      if (n_ranks > 1) then
        if (is_root()) then
          do g = -1, asm%ngroups - 1
            call partition_into(pack([(i, i=1, size(active))], bgroup == g), &
                                merge(n_ranks, (n_ranks - 1 - g)/asm%ngroups + 1, g < 0))
            if (allocated(err)) exit
          end do
          if (allocated(err)) part = -1   ! tell the other ranks, so that none waits forever
        end if
        call bcast_int(part)
        if (any(part < 0)) then
          if (.not. allocated(err)) call fatal_error(err, 'element partition failed on rank 0')
          return
        end if
      end if
      owner(active) = merge(part, bgroup + asm%ngroups*part, bgroup < 0)
    end if
    asm%owned = pack([(e, e=1, model%nelem)], owner == my_rank)
    asm%dealt = pack(active, [(mod(i, n_ranks) == my_rank, i=1, size(active))])
    asm%elems = [pack(active, owner(active) == my_rank .and. bgroup >= 0), &
                 pack(active, owner(active) == my_rank .and. bgroup < 0)]
    allocate (asm%estart(size(asm%elems) + 1))
    ! count, then fill; each block's entries in one stretch
    k = 0
    do i = 1, size(asm%elems)
      asm%estart(i) = k + 1
      d = element_dofs(model, asm%elems(i))
      do j = 1, ndof_elem
        ib = asm%eq(d(j)); if (ib == 0) cycle
        do n = 1, ndof_elem
          ia = asm%eq(d(n))
          if (ia >= ib) k = k + 1
        end do
      end do
    end do
    asm%estart(size(asm%elems) + 1) = k + 1
    allocate (asm%pos(k), asm%irn(k), asm%jcn(k), asm%a(k))
    k = 0
    do i = 1, size(asm%elems)
      d = element_dofs(model, asm%elems(i))
      s = merge(1, 2, group(model%elem_body(asm%elems(i))) >= 0)
      if (asm%blk(s)%last < asm%blk(s)%first) asm%blk(s)%first = k + 1
      off = asm%blk(s)%off
      do j = 1, ndof_elem
        ib = asm%eq(d(j)); if (ib == 0) cycle
        do n = 1, ndof_elem
          ia = asm%eq(d(n))
          if (ia < ib) cycle
          k = k + 1
          asm%pos(k) = n + ndof_elem*(j - 1); asm%irn(k) = ia - off; asm%jcn(k) = ib - off
        end do
      end do
      asm%blk(s)%last = k
    end do
  contains
    !> group(b) for ng groups, the nshared smallest bodies shared by all ranks (group -1),
    !> the others the largest first to the group whose ranks are least loaded; load(g) =
    !> unknowns per rank of group g (replicated, so alike everywhere); a group left without
    !> a body of its own makes the dealing fail (load huge)
    subroutine deal(ng, nshared)
      integer, intent(in) :: ng, nshared
      integer :: left(model%nbody), size_g(ng), bb, gg, m
      size_g = [((n_ranks - 1 - gg)/ng + 1, gg=0, ng - 1)]
      if (allocated(load)) deallocate (load)
      allocate (load(ng))
      load = 0; group = 0; left = nfree
      do m = 1, nshared
        bb = minloc(left, dim=1, mask=left > 0)
        group(bb) = -1; load = load + real(left(bb), dp)/n_ranks
        left(bb) = 0
      end do
      do
        bb = maxloc(left, dim=1, mask=left > 0)
        if (bb == 0) exit
        gg = minloc(load + real(left(bb), dp)/size_g, dim=1)
        group(bb) = gg - 1; load(gg) = load(gg) + real(left(bb), dp)/size_g(gg)
        left(bb) = 0
      end do
      do gg = 0, ng - 1
        if (.not. any(group == gg .and. nfree > 0)) load = huge(1._dp)
      end do
    end subroutine deal

    !> part(idx) = 0..nparts-1: a block's active elements active(idx) over its nparts ranks
    subroutine partition_into(idx, nparts)
      integer, intent(in) :: idx(:), nparts
      integer, allocatable :: p(:)
      if (nparts <= 1 .or. size(idx) == 0) return
      allocate (p(size(idx)))
      call partition_elements(model%conn(:, active(idx)), model%nnode, nparts, p, err)
      part(idx) = p
    end subroutine partition_into
  end subroutine assembly_setup

  !> r = f_int(q) + cm M q - M qs  (qs, cm only in dynamics), summed over ranks, and
  !> (want_k) asm%a = H + cm M. energy: strain energy of q (sum over ranks). With qn and af
  !> (generalized-alpha, casca_time_scheme) f_int and H are taken at (1 - af) q + af qn and
  !> H is scaled by 1 - af, its derivative with respect to q. The tangent goes
  !> to the blocks' MUMPS instances, so with want_k the elements are this rank's of its blocks;
  !> without, any split will do and the elements dealt round keep the ranks evenly loaded.
  subroutine assemble(model, asm, q, want_k, r, energy, cm, qs, qn, af)
    type(model_t), intent(in) :: model
    type(assembly_t), intent(inout) :: asm
    real(dp), intent(in) :: q(:)
    logical, intent(in) :: want_k
    real(dp), intent(out) :: r(:), energy
    real(dp), intent(in), optional :: cm, qs(:), qn(:), af
    real(dp) :: qe(7, 10), fe(ndof_elem), ke(ndof_elem, ndof_elem), ue, me(20, 20), acc(3, 20)
    real(dp) :: w
    integer :: d(ndof_elem), i, e, b, p, l
    logical :: dynamic, blend

    dynamic = present(cm)
    w = 0
    if (present(af)) w = af
    blend = w /= 0 .and. present(qn)
    r = 0; energy = 0
    do i = 1, merge(size(asm%elems), size(asm%dealt), want_k)
      if (want_k) then
        e = asm%elems(i)
      else
        e = asm%dealt(i)
      end if
      d = element_dofs(model, e)
      qe = reshape(q(d), [7, 10])
      if (blend) qe = (1 - w)*qe + w*reshape(qn(d), [7, 10])
      b = model%elem_body(e)
      call shell_energy_force(model%rule, model%body(b)%thickness, model%body(b)%lam, &
                              model%body(b)%mu, model%binv(:, :, :, e), model%wdet(:, e), qe, &
                              want_k, ue, fe, ke)
      energy = energy + ue
      if (blend) then
        if (want_k) ke = (1 - w)*ke
        qe = reshape(q(d), [7, 10])   ! (the inertia is of the end of the step)
      end if
      if (dynamic) then
        ! inertia of the vector parameters (Y^l, G^l): M (cm q - qs), tangent cm M
        me = model%emass(:, :, e)
        acc(:, 1:10) = cm*qe(1:3, :) - qs_part(1)
        acc(:, 11:20) = cm*qe(4:6, :) - qs_part(4)
        acc = matmul(acc, me)
        do l = 1, 10
          fe(7*l - 6:7*l - 4) = fe(7*l - 6:7*l - 4) + acc(:, l)
          fe(7*l - 3:7*l - 1) = fe(7*l - 3:7*l - 1) + acc(:, 10 + l)
        end do
        if (want_k) call add_mass(ke, cm*me)
      end if
      r(d) = r(d) + fe
      if (want_k) then
        do p = asm%estart(i), asm%estart(i + 1) - 1
          asm%a(p) = ke(mod(asm%pos(p) - 1, ndof_elem) + 1, (asm%pos(p) - 1)/ndof_elem + 1)
        end do
      end if
    end do
    call sum_all(r)
    call sum_all(energy)
  contains
    !> the 3 x 10 block of qs for components c..c+2 of the element's nodes
    function qs_part(c) result(v)
      integer, intent(in) :: c
      real(dp) :: v(3, 10)
      integer :: ll
      do ll = 1, 10
        v(:, ll) = qs(d(7*(ll - 1) + c):d(7*(ll - 1) + c + 2))
      end do
    end function qs_part
  end subroutine assemble

  !> Strain energy of q per body (sum over ranks), balanced over the ranks whatever the groups.
  function strain_energy(model, asm, q) result(energy)
    type(model_t), intent(in) :: model
    type(assembly_t), intent(in) :: asm
    real(dp), intent(in) :: q(:)
    real(dp) :: energy(model%nbody)
    call strain_energy_local(model, asm, q, energy)
    call sum_all(energy)
  end function strain_energy

  !> This rank's share of the strain energy of q per body, not summed over the ranks: for a
  !> caller that sums it with other figures in one reduction (casca_accounting).
  subroutine strain_energy_local(model, asm, q, energy)
    type(model_t), intent(in) :: model
    type(assembly_t), intent(in) :: asm
    real(dp), intent(in) :: q(:)
    real(dp), intent(out) :: energy(:)   !< (nbody)
    integer :: i, e, b
    energy = 0
    do i = 1, size(asm%dealt)
      e = asm%dealt(i)
      b = model%elem_body(e)
      energy(b) = energy(b) + element_energy(model, q, e)
    end do
  end subroutine strain_energy_local

  !> ke += m (x) I3 on the (Y, G) parameters
  pure subroutine add_mass(ke, m)
    real(dp), intent(inout) :: ke(ndof_elem, ndof_elem)
    real(dp), intent(in) :: m(20, 20)
    integer :: p, q, c, ip, iq
    do q = 1, 20
      iq = 7*(mod(q - 1, 10)) + merge(0, 3, q <= 10)
      do p = 1, 20
        ip = 7*(mod(p - 1, 10)) + merge(0, 3, p <= 10)
        do c = 1, 3
          ke(ip + c, iq + c) = ke(ip + c, iq + c) + m(p, q)
        end do
      end do
    end do
  end subroutine add_mass
end module casca_assembly
