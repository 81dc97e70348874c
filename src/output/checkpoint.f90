!> Restart checkpoints of a run: the state, the step-cut level, the contact active set
!> (each constraint's node, pair, point, side, faces, multiplier and acceleration correction)
!> and the pressures' work on open surfaces (a sum over the steps, casca_accounting),
!> with a fingerprint of the model they belong to (mesh, materials, restraints) and a checksum
!> of the state. A checkpoint is read back only when its fingerprint is this deck's, every
!> field is in range and its contents match their checksum; a state
!> that is not finite is never written (the last good checkpoint stays). The file format is
!> casca_hdf5_io's.
module casca_checkpoint
  use, intrinsic :: iso_fortran_env, only: int32, int64
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use casca_kinds, only: dp
  use casca_error, only: error_t, fatal_error
  use casca_model, only: model_t
  use casca_newmark, only: state_t
  use casca_contact, only: contact_t, new_constraint, around_rim
  use casca_contact_projection, only: positions, constraint_geometry
  use casca_hdf5_io, only: write_checkpoint, read_checkpoint
  use casca_mpi, only: is_root
  use casca_strings, only: itoa
  implicit none
  private
  public :: save_checkpoint, load_checkpoint, model_fingerprint

contains

  !> Two 31-bit hashes (different multipliers, modulo the prime 2^31 - 1) of the model's
  !> counts, coordinates, connectivity, materials and prescribed parameters: another mesh,
  !> material or restraint gives another fingerprint (not a cryptographic one).
  function model_fingerprint(model) result(fp)
    type(model_t), intent(in) :: model
    integer :: fp(2)
    integer(int64) :: h(2)
    integer :: b
    h = 1
    call mix(h, [model%nnode, model%nelem, model%ndof, model%nbody])
    call mix(h, transfer(model%x0, [0_int32]))
    call mix(h, reshape(model%conn, [size(model%conn)]))
    call mix(h, merge(1, 0, model%fixed))
    do b = 1, model%nbody
      call mix(h, transfer([model%body(b)%young, model%body(b)%poisson, model%body(b)%density, &
                            model%body(b)%thickness], [0_int32]))
    end do
    fp = int(h)
  end function model_fingerprint

  !> The same two hashes of everything a checkpoint holds of the run's state: a file changed
  !> or damaged after it was written (a flipped bit in q) is refused, not run from
  function state_checksum(st, ints, reals) result(cs)
    type(state_t), intent(in) :: st
    integer, intent(in) :: ints(:)
    real(dp), intent(in) :: reals(:)
    integer :: cs(2)
    integer(int64) :: h(2)
    h = 1
    call mix(h, [st%step, size(ints), size(reals)])
    call mix(h, transfer([st%t, st%q, st%qd, st%qdd, reals], [0_int32]))
    call mix(h, ints)
    cs = int(h)
  end function state_checksum

  pure subroutine mix(h, w)
    integer(int64), intent(inout) :: h(2)
    integer(int32), intent(in) :: w(:)
    integer(int64), parameter :: p = 2147483647_int64, a(2) = [1103515245_int64, 69069_int64]
    integer :: i
    do i = 1, size(w)   ! a word as 0 .. 2^32-1, so h*a + w < 2^63: no overflow
      h = mod(h*a + iand(int(w(i), int64), 4294967295_int64), p)
    end do
  end subroutine mix

  !> Write the checkpoint path (rank 0; the caller shares err): refused if the state or the
  !> multipliers are not finite.
  subroutine save_checkpoint(path, model, st, level, pressure_work, contact, err, dt_next, cap)
    character(len=*), intent(in) :: path
    type(model_t), intent(in) :: model
    type(state_t), intent(in) :: st
    integer, intent(in) :: level
    real(dp), intent(in) :: pressure_work   !< of open pressures and moments so far (balance_t%path_work)
    type(contact_t), intent(in), optional :: contact
    type(error_t), allocatable, intent(out) :: err
    real(dp), intent(in), optional :: dt_next   !< the next step (error-controlled runs)
    !> and the energy's cap on it (huge: none), when it was set or last doubled, and the
    !> energy the last step made (casca_run's energy_accepted)
    real(dp), intent(in), optional :: cap(3)
    integer, allocatable :: ints(:)
    real(dp), allocatable :: reals(:), last(:)
    integer :: k, nact
    if (.not. is_root()) return
    nact = 0
    if (present(contact)) nact = contact%set%nact
    if (.not. (all(ieee_is_finite(st%q)) .and. all(ieee_is_finite(st%qd)) .and. &
               all(ieee_is_finite(st%qdd)) .and. ieee_is_finite(st%t))) then
      call fatal_error(err, path//' not written: the state at step '//itoa(st%step)// &
                       ' is not finite (the earlier checkpoint, if any, is kept)'); return
    end if
    if (present(contact)) then
      if (.not. (all(ieee_is_finite(contact%set%act(1:nact)%lambda)) .and. &
                 all(ieee_is_finite(contact%set%act(1:nact)%mu)))) then
        call fatal_error(err, path//' not written: contact forces at step '//itoa(st%step)// &
                         ' are not finite (the earlier checkpoint, if any, is kept)'); return
      end if
      ! per constraint: node, pair, target element, the side of the target and the two faces
      ! it holds; then the multipliers lambda, the acceleration's corrections mu and the
      ! points xi. The point, side and faces are held within a step, and a constraint
      ! released in the step after a restart pushes along its row of the step before
      ! (newmark.f90): chosen again at the restart they made another run (two rings, the
      ! trapezoidal rule: kinetic energy 0.03% off in that step, 14% later). With friction,
      ! the stick/slip state, the stick multipliers and their corrections, the slip
      ! direction; then the work summed so far (friction per pair, moving obstacles); last
      ! per pair the impulse so far and the start force of the next step (rows.f90); then
      ! friction's start force per constraint (friction.f90), the depths held, and per pair
      ! the kinetic energy the velocity corrections took out so far.
      associate (a => contact%set%act(1:nact))
        ints = [level, nact, (a(k)%node, a(k)%pair, a(k)%elem, a(k)%side, a(k)%face, a(k)%grip, k=1, nact)]
        reals = [a%lambda, a%mu, (a(k)%xi, a(k)%lt, a(k)%mut, a(k)%s, k=1, nact), contact%friction_work, &
                 contact%obstacle_work, contact%impulse, contact%carry, (a(k)%fa, k=1, nact), a%hold, &
                 contact%correction_loss]
      end associate
    else
      ints = [level, 0]
      allocate (reals(0))
    end if
    ! (the last step's length and start acceleration, which the next step's start follows
    ! if its length differs: casca_time_scheme's moved_start; none: not written)
    last = [real(dp) ::]
    if (st%h_last > 0) last = [st%h_last, st%qdd_last]
    call write_checkpoint(path, st%t, st%step, st%q, st%qd, st%qdd, ints, reals, err, &
                          model_fingerprint(model), dt_next, &
                          state_checksum(st, ints, [reals, pressure_work]), cap, pressure_work, last)
  end subroutine save_checkpoint

  !> Read the checkpoint path into st, level and the contact active set, after checking that
  !> it belongs to this model and that every field is in range: 0 <= t <= t_max, step >= 0,
  !> 0 <= level <= max_level, each constraint an impactor node of one of the contact pairs.
  subroutine load_checkpoint(path, model, t_max, max_level, st, level, err, contact, dt_next, cap, &
                             pressure_work)
    character(len=*), intent(in) :: path
    type(model_t), intent(in) :: model
    real(dp), intent(in) :: t_max
    integer, intent(in) :: max_level
    type(state_t), intent(inout) :: st
    integer, intent(out) :: level
    type(error_t), allocatable, intent(out) :: err
    type(contact_t), intent(inout), optional :: contact
    real(dp), intent(out), optional :: dt_next   !< 0: not in the checkpoint
    real(dp), intent(out), optional :: cap(3)    !< [huge, 0, 0]: not in the checkpoint
    !> the pressures' work on open surfaces so far (0: not in the checkpoint, which one
    !> written before it was kept or of a scene without such pressures is)
    real(dp), intent(out), optional :: pressure_work
    real(dp), allocatable :: pw
    integer, allocatable :: ints(:), fp(:), cs(:)
    real(dp), allocatable :: cp(:)   ! (the energy's cap, when it was set, the last step's energy)
    real(dp), allocatable :: reals(:), last(:)
    integer :: k, nact, node, pair, per
    character(len=:), allocatable :: bad
    logical :: with_fa, with_hold

    level = 0
    call read_checkpoint(path, st%t, st%step, st%q, st%qd, st%qdd, ints, reals, err, fp, dt_next, cs, &
                         cp, pw, last)
    if (allocated(err)) return
    if (present(pressure_work)) pressure_work = 0
    bad = ''
    if (.not. allocated(fp)) then
      bad = 'it has no model fingerprint (written by an older casca)'
    else if (size(fp) /= 2 .or. size(st%q) /= model%ndof) then
      bad = 'it belongs to another model'
    else if (any(fp /= model_fingerprint(model))) then
      bad = 'it belongs to another model (mesh, materials or restraints differ from the deck''s)'
    else if (.not. (st%t >= 0 .and. st%t <= t_max*(1 + 1e-9_dp))) then   ! (a sum of steps: rounding)
      bad = 'its time is outside [0, t_end]'
    else if (st%step < 0) then
      bad = 'its step number is negative'
    else if (.not. (all(ieee_is_finite(st%q)) .and. all(ieee_is_finite(st%qd)) .and. &
                    all(ieee_is_finite(st%qdd)))) then
      bad = 'its state is not finite'
    else if (size(ints) < 2) then
      bad = 'it has no step-cut level and contact count'
    else if (ints(1) < 0 .or. ints(1) > max_level) then
      bad = 'its step-cut level '//itoa(ints(1))//' is outside [0, max_step_cuts = '// &
            itoa(max_level)//']'
    end if
    if (bad == '' .and. present(dt_next)) then
      if (.not. (dt_next >= 0 .and. dt_next <= t_max)) bad = 'its next step is outside [0, t_end]'
    end if
    ! (a checkpoint written before the last step's energy was kept has 2 numbers: it is 0)
    if (present(cap)) cap = [huge(1._dp), 0._dp, 0._dp]
    if (bad == '' .and. allocated(cp)) then
      if (size(cp) /= 2 .and. size(cp) /= 3) then
        bad = 'its cap on the steps has '//itoa(size(cp))//' numbers, not 3'
      else if (.not. (cp(1) > 0 .and. cp(2) >= 0 .and. cp(2) <= t_max .and. ieee_is_finite(cp(size(cp))))) then
        bad = 'its cap on the steps is not positive, was set outside [0, t_end] or has an energy not finite'
      else if (present(cap)) then
        cap(1:size(cp)) = cp
      end if
    end if
    st%h_last = 0
    if (bad == '' .and. allocated(last)) then
      if (size(last) /= model%ndof + 1 .or. .not. all(ieee_is_finite(last)) .or. .not. last(1) > 0) then
        bad = 'its last step (length and start acceleration) has '//itoa(size(last))// &
              ' numbers, not '//itoa(model%ndof + 1)//', or is not finite or not positive'
      else
        st%h_last = last(1); st%qdd_last = last(2:)
      end if
    end if
    if (bad == '') then
      level = ints(1); nact = ints(2)
      if (nact < 0 .or. (nact > 0 .and. .not. present(contact))) then
        bad = 'its contact count '//itoa(nact)//' does not fit the deck''s contact pairs'
      end if
    end if
    ! 7 integers (node, pair, elem, side, faces, grip) and 2 + 9 reals (lambda, mu; xi, lt,
    ! mut, s) per constraint, then the works (npairs + 1), the impulses (6 npairs),
    ! friction's start forces (3 nact), the depths held (nact) and the velocity corrections'
    ! losses (npairs) (the last four absent from earlier checkpoints: taken as 0); a
    ! checkpoint of casca before these were kept has 2 and 1 (node, pair; lambda): it is read,
    ! point, side and faces chosen again at the restart, mu taken as 0, the works as 0
    per = 7
    if (bad == '' .and. present(contact)) then
      if (size(ints) == 2 + 2*int(nact, int64) .and. size(reals) == nact) then
        per = 2
      else if (size(ints) /= 2 + 7*int(nact, int64) .or. &
               (size(reals) /= 11*int(nact, int64) + contact%npairs + 1 .and. &
                size(reals) /= 11*int(nact, int64) + 7*contact%npairs + 1 .and. &
                size(reals) /= 14*int(nact, int64) + 7*contact%npairs + 1 .and. &
                size(reals) /= 15*int(nact, int64) + 7*contact%npairs + 1 .and. &
                size(reals) /= 15*int(nact, int64) + 8*contact%npairs + 1)) then
        bad = 'its contact count '//itoa(nact)//' does not match its contact data'
      end if
      if (bad == '' .and. .not. all(ieee_is_finite(reals))) bad = 'its contact forces are not finite'
    end if
    do k = 1, merge(nact, 0, bad == '')
      node = ints(3 + per*(k - 1)); pair = ints(4 + per*(k - 1))
      if (pair < 1 .or. pair > contact%npairs) then
        bad = 'contact '//itoa(k)//' names pair '//itoa(pair)//' of '//itoa(contact%npairs)
      else if (node < model%body(contact%pair(1, pair))%node_first .or. &
               node > model%body(contact%pair(1, pair))%node_last) then
        bad = 'contact '//itoa(k)//' names node '//itoa(node)//', not of the pair''s impactor'
      else if (per == 7) then
        associate (e => ints(5 + per*(k - 1)), sd => ints(6 + per*(k - 1)), &
                   f => ints(7 + per*(k - 1):8 + per*(k - 1)), bt => contact%pair(2, pair), &
                   grip => ints(9 + per*(k - 1)))
          if ((abs(sd) > 1 .and. sd /= around_rim) .or. any(f < -1) .or. any(f > 2) .or. grip < 0 .or. grip > 2) then
            bad = 'contact '//itoa(k)//' has side '//itoa(sd)//', faces '//itoa(f(1))//', '// &
                  itoa(f(2))//' or grip '//itoa(grip)//' out of range (side -1, 0, 1, '//itoa(around_rim)//'; face -1, 0, '// &
                  '1, 2; grip 0, 1, 2)'
          else if (e /= 0 .and. bt <= 0) then
            bad = 'contact '//itoa(k)//' names element '//itoa(e)//' on an obstacle'
          else if (bt > 0) then
            if (e /= 0 .and. (e < model%body(max(bt, 1))%elem_first .or. &
                              e > model%body(max(bt, 1))%elem_last)) &
              bad = 'contact '//itoa(k)//' names element '//itoa(e)//', not of the pair''s target'
          end if
          if (bad == '' .and. any(abs(reals(2*nact + 9*k - 8:2*nact + 9*k - 7)) > 10)) &
            bad = 'contact '//itoa(k)//' has its point far outside its element'
        end associate
      end if
      if (bad /= '') exit
    end do
    if (bad == '' .and. allocated(cs)) then   ! (last: the checks above name what is out of range)
      if (size(cs) /= 2) then
        bad = 'its checksum is not two numbers'
      else if (any(cs /= checksum_read())) then
        bad = 'its contents do not match their checksum (the file was changed or damaged '// &
              'after casca wrote it)'
      end if
    end if
    if (bad /= '') then
      call fatal_error(err, path//': not a checkpoint of this deck: '//bad); return
    end if
    if (.not. allocated(cs) .and. is_root()) write (0, '(a)') 'warning: '//path// &
      ' has no checksum (written by an older casca): its contents cannot be checked'
    if (allocated(pw)) then
      if (.not. ieee_is_finite(pw)) then
        call fatal_error(err, path//': not a checkpoint of this deck: its pressure work is not finite')
        return
      end if
      if (present(pressure_work)) pressure_work = pw
    end if

    if (.not. present(contact)) return
    contact%set%nact = nact   ! the active set
    if (allocated(contact%set%act)) then
      if (size(contact%set%act) < nact) deallocate (contact%set%act)
    end if
    if (.not. allocated(contact%set%act)) allocate (contact%set%act(nact))
    contact%time = st%t   ! (obstacles where they are at the checkpoint)
    if (per == 7) then
      contact%friction_work = reals(11*nact + 1:11*nact + contact%npairs)
      contact%obstacle_work = reals(11*nact + contact%npairs + 1)
      if (size(reals) > 11*nact + contact%npairs + 1) then
        associate (at => 11*nact + contact%npairs + 1, np => contact%npairs)
          contact%impulse = reshape(reals(at + 1:at + 3*np), [3, np])
          contact%carry = reshape(reals(at + 3*np + 1:at + 6*np), [3, np])
        end associate
      end if
      ! (friction measures slip from the step's start: a dynamic run's constraints only
      ! carry a grip)
      if (any(ints(9:2 + per*nact:per) /= 0)) then
        contact%x_start = positions(model, st%q); contact%dt = 0
        contact%g_start = positions(model, st%q, fibres=.true.)
      end if
    end if
    with_fa = size(reals) >= 14*int(nact, int64) + 7*contact%npairs + 1   ! (friction's start forces)
    with_hold = size(reals) >= 15*int(nact, int64) + 7*contact%npairs + 1   ! (the depths held)
    if (size(reals) == 15*int(nact, int64) + 8*contact%npairs + 1) &   ! (the corrections' loss)
      contact%correction_loss = reals(15*nact + 7*contact%npairs + 2:)
    do k = 1, nact
      contact%set%act(k) = new_constraint(ints(3 + per*(k - 1)), ints(4 + per*(k - 1)))
      associate (a => contact%set%act(k))
        a%lambda = reals(k)   ! the multipliers start each step from the last
        if (per == 2) cycle   ! (elem = 0: projected again at the first step)
        a%elem = ints(5 + per*(k - 1))
        a%side = ints(6 + per*(k - 1))
        a%face = ints(7 + per*(k - 1):8 + per*(k - 1))
        a%grip = ints(9 + per*(k - 1))
        a%mu = reals(nact + k)
        associate (r => reals(2*nact + 9*k - 8:2*nact + 9*k))
          a%xi = r(1:2); a%lt = r(3:4); a%mut = r(5:6)
          a%s = r(7:9)
        end associate
        if (with_fa) then
          associate (at => 11*nact + 7*contact%npairs + 1 + 3*(k - 1))
            a%fa = reals(at + 1:at + 3)
          end associate
        end if
        if (with_hold) a%hold = reals(14*nact + 7*contact%npairs + 1 + k)
        ! normal, shape functions, offset and gap at the checkpoint's positions, as the step
        ! that wrote it left them
        if (a%elem > 0 .or. contact%pair(2, a%pair) <= 0) &
          call constraint_geometry(contact, model, positions(model, st%q), st%q, a, lever=.true.)
      end associate
    end do
  contains
    !> the checksum of what was read (the pressure work with the reals, as save_checkpoint)
    function checksum_read() result(c)
      integer :: c(2)
      if (allocated(pw)) then
        c = state_checksum(st, ints, [reals, pw])
      else
        c = state_checksum(st, ints, reals)
      end if
    end function checksum_read
  end subroutine load_checkpoint
end module casca_checkpoint
