!> Restart checkpoints of a run: the state, the step-cut level and the contact active set,
!> with a fingerprint of the model they belong to (mesh, materials, restraints). A checkpoint
!> is read back only when its fingerprint is this deck's and every field is in range; a state
!> that is not finite is never written (the last good checkpoint stays). The file format is
!> casca_hdf5_io's.
module casca_checkpoint
  use, intrinsic :: iso_fortran_env, only: int32, int64
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use casca_kinds, only: dp
  use casca_error, only: error_t, fatal_error
  use casca_model, only: model_t
  use casca_newmark, only: state_t
  use casca_contact, only: contact_t
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
    integer(int64), parameter :: p = 2147483647_int64, a(2) = [1103515245_int64, 69069_int64]
    integer(int64) :: h(2)
    integer :: b
    h = 1
    call mix([model%nnode, model%nelem, model%ndof, model%nbody])
    call mix(transfer(model%x0, [0_int32]))
    call mix(reshape(model%conn, [size(model%conn)]))
    call mix(merge(1, 0, model%fixed))
    do b = 1, model%nbody
      call mix(transfer([model%body(b)%young, model%body(b)%poisson, model%body(b)%density, &
                         model%body(b)%thickness], [0_int32]))
    end do
    fp = int(h)
  contains
    subroutine mix(w)
      integer(int32), intent(in) :: w(:)
      integer :: i
      do i = 1, size(w)   ! a word as 0 .. 2^32-1, so h*a + w < 2^63: no overflow
        h = mod(h*a + iand(int(w(i), int64), 4294967295_int64), p)
      end do
    end subroutine mix
  end function model_fingerprint

  !> Write the checkpoint path (rank 0; the caller shares err): refused if the state or the
  !> multipliers are not finite.
  subroutine save_checkpoint(path, model, st, level, contact, err)
    character(len=*), intent(in) :: path
    type(model_t), intent(in) :: model
    type(state_t), intent(in) :: st
    integer, intent(in) :: level
    type(contact_t), intent(in), optional :: contact
    type(error_t), allocatable, intent(out) :: err
    integer :: k, nact
    if (.not. is_root()) return
    nact = 0
    if (present(contact)) nact = contact%nact
    if (.not. (all(ieee_is_finite(st%q)) .and. all(ieee_is_finite(st%qd)) .and. &
               all(ieee_is_finite(st%qdd)) .and. ieee_is_finite(st%t))) then
      call fatal_error(err, path//' not written: the state at step '//itoa(st%step)// &
                       ' is not finite (the earlier checkpoint, if any, is kept)'); return
    end if
    if (nact > 0) then
      if (.not. all(ieee_is_finite(contact%act(1:nact)%lambda))) then
        call fatal_error(err, path//' not written: contact forces at step '//itoa(st%step)// &
                         ' are not finite (the earlier checkpoint, if any, is kept)'); return
      end if
      call write_checkpoint(path, st%t, st%step, st%q, st%qd, st%qdd, &
                            [level, nact, (contact%act(k)%node, contact%act(k)%pair, k=1, nact)], &
                            contact%act(1:nact)%lambda, err, model_fingerprint(model))
    else
      call write_checkpoint(path, st%t, st%step, st%q, st%qd, st%qdd, [level, 0], &
                            [real(dp) ::], err, model_fingerprint(model))
    end if
  end subroutine save_checkpoint

  !> Read the checkpoint path into st, level and the contact active set, after checking that
  !> it belongs to this model and that every field is in range: 0 <= t <= t_max, step >= 0,
  !> 0 <= level <= max_level, each constraint an impactor node of one of the contact pairs.
  subroutine load_checkpoint(path, model, t_max, max_level, st, level, err, contact)
    character(len=*), intent(in) :: path
    type(model_t), intent(in) :: model
    real(dp), intent(in) :: t_max
    integer, intent(in) :: max_level
    type(state_t), intent(inout) :: st
    integer, intent(out) :: level
    type(error_t), allocatable, intent(out) :: err
    type(contact_t), intent(inout), optional :: contact
    integer, allocatable :: ints(:), fp(:)
    real(dp), allocatable :: reals(:)
    integer :: k, nact, node, pair
    character(len=:), allocatable :: bad

    level = 0
    call read_checkpoint(path, st%t, st%step, st%q, st%qd, st%qdd, ints, reals, err, fp)
    if (allocated(err)) return
    bad = ''
    if (.not. allocated(fp)) then
      bad = 'it has no model fingerprint (written by an older casca)'
    else if (size(fp) /= 2 .or. size(st%q) /= model%ndof) then
      bad = 'it belongs to another model'
    else if (any(fp /= model_fingerprint(model))) then
      bad = 'it belongs to another model (mesh, materials or restraints differ from the deck''s)'
    else if (.not. (st%t >= 0 .and. st%t <= t_max)) then
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
    if (bad == '') then
      level = ints(1); nact = ints(2)
      if (nact < 0 .or. (nact > 0 .and. .not. present(contact))) then
        bad = 'its contact count '//itoa(nact)//' does not fit the deck''s contact pairs'
      else if (size(ints) /= 2 + 2*int(nact, int64) .or. size(reals) /= nact) then
        bad = 'its contact count '//itoa(nact)//' does not match its contact data'
      else if (.not. all(ieee_is_finite(reals))) then
        bad = 'its contact forces are not finite'
      end if
    end if
    do k = 1, merge(nact, 0, bad == '')
      node = ints(1 + 2*k); pair = ints(2 + 2*k)
      if (pair < 1 .or. pair > contact%npairs) then
        bad = 'contact '//itoa(k)//' names pair '//itoa(pair)//' of '//itoa(contact%npairs)
      else if (node < model%body(contact%pair(1, pair))%node_first .or. &
               node > model%body(contact%pair(1, pair))%node_last) then
        bad = 'contact '//itoa(k)//' names node '//itoa(node)//', not of the pair''s impactor'
      end if
      if (bad /= '') exit
    end do
    if (bad /= '') then
      call fatal_error(err, path//': not a checkpoint of this deck: '//bad); return
    end if
    if (.not. present(contact)) return
    contact%nact = nact   ! the active set: (node, pair) per constraint
    if (allocated(contact%act)) then
      if (size(contact%act) < nact) deallocate (contact%act)
    end if
    if (.not. allocated(contact%act)) allocate (contact%act(nact))
    do k = 1, nact
      contact%act(k)%node = ints(1 + 2*k); contact%act(k)%pair = ints(2 + 2*k)
      contact%act(k)%elem = 0
      contact%act(k)%lambda = reals(k)   ! the multipliers start each step from the last
    end do
  end subroutine load_checkpoint
end module casca_checkpoint
