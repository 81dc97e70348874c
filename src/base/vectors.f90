!> Small vector helpers shared by the element, the model, contact and I/O.
module casca_vectors
  use casca_kinds, only: dp
  implicit none
  private
  public :: cross, sort_index

contains

  pure function cross(a, b) result(c)
    real(dp), intent(in) :: a(3), b(3)
    real(dp) :: c(3)
    c = [a(2)*b(3) - a(3)*b(2), a(3)*b(1) - a(1)*b(3), a(1)*b(2) - a(2)*b(1)]
  end function cross

  !> Stable bottom-up merge sort: order is the permutation that sorts key ascending (node
  !> positions along a line, Gmsh's node tags)
  pure subroutine sort_index(key, order)
    real(dp), intent(in) :: key(:)
    integer, allocatable, intent(out) :: order(:)
    integer, allocatable :: tmp(:)
    integer :: n, width, lo, mid, hi, i, j, k
    n = size(key)
    allocate (order(n), tmp(n))
    order = [(i, i=1, n)]
    width = 1
    do while (width < n)
      do lo = 1, n, 2*width
        mid = min(lo + width - 1, n); hi = min(lo + 2*width - 1, n)
        i = lo; j = mid + 1
        do k = lo, hi
          if (j > hi) then
            tmp(k) = order(i); i = i + 1
          else if (i > mid) then
            tmp(k) = order(j); j = j + 1
          else if (key(order(i)) <= key(order(j))) then
            tmp(k) = order(i); i = i + 1
          else
            tmp(k) = order(j); j = j + 1
          end if
        end do
      end do
      order = tmp
      width = 2*width
    end do
  end subroutine sort_index
end module casca_vectors
