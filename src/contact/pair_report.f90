!> Per contact pair, for the history: the normal force resultant (the sum of -lambda over the
!> pair's active constraints: positive in compression, the pair's share of the total contact
!> force) and the number of active constraints, and a label naming each pair by its two sides.
!> The sides' names come from the caller, as an array over the sides' indices: a target need
!> not be a body (an obstacle, index <= 0) and may be the impactor itself (self-contact), so
!> nothing here indexes the bodies. (An array, not a procedure: an internal procedure passed
!> as an argument needs an executable stack for its trampoline.)
module casca_pair_report
  use casca_kinds, only: dp
  use casca_contact, only: contact_t
  implicit none
  private
  public :: pair_normal_force, pair_active_count, pair_labels

contains

  !> (npairs) sum of -lambda over each pair's active constraints [N]
  pure function pair_normal_force(c) result(fn)
    type(contact_t), intent(in) :: c
    real(dp) :: fn(c%npairs)
    integer :: k
    fn = 0
    do k = 1, c%set%nact
      fn(c%set%act(k)%pair) = fn(c%set%act(k)%pair) - c%set%act(k)%lambda
    end do
  end function pair_normal_force

  !> (npairs) active constraints of each pair
  pure function pair_active_count(c) result(n)
    type(contact_t), intent(in) :: c
    integer :: n(c%npairs)
    integer :: k
    n = 0
    do k = 1, c%set%nact
      n(c%set%act(k)%pair) = n(c%set%act(k)%pair) + 1
    end do
  end function pair_active_count

  !> 'impactor_target' for each pair (2, npairs); names(k - first + 1) names side k (trimmed),
  !> a side outside names is 'side<k>'.
  pure subroutine pair_labels(pair, names, first, labels)
    integer, intent(in) :: pair(:, :)
    character(len=*), intent(in) :: names(:)
    integer, intent(in) :: first
    character(len=:), allocatable, intent(out) :: labels(:)
    integer :: p, n
    n = 1
    do p = 1, size(pair, 2)
      n = max(n, len(side(pair(1, p))) + 1 + len(side(pair(2, p))))
    end do
    allocate (character(len=n) :: labels(size(pair, 2)))
    do p = 1, size(pair, 2)
      labels(p) = side(pair(1, p))//'_'//side(pair(2, p))
    end do
  contains
    pure function side(k) result(name)
      integer, intent(in) :: k
      character(len=:), allocatable :: name
      character(len=16) :: num
      if (k - first + 1 >= 1 .and. k - first + 1 <= size(names)) then
        name = trim(names(k - first + 1))
      else
        write (num, '(i0)') k
        name = 'side'//trim(num)
      end if
    end function side
  end subroutine pair_labels
end module casca_pair_report
