!> The active constraints as the equations see them: the rows of C for the saddle point, and
!> the contact forces C^T lambda they carry.
module casca_contact_rows
  use casca_kinds, only: dp
  use casca_model, only: model_t, dof
  use casca_contact, only: contact_t
  use casca_contact_projection, only: constraint_entries, constraint_row, max_row
  implicit none
  private
  public :: contact_rows, contact_generalized_force, contact_force_total, contact_nodal_fields


contains

  !> Constraint rows for MUMPS: entries (neq + k, eq) of dg_k/dq (irn > jcn), a zero
  !> diagonal for each multiplier, and the gaps.
  subroutine contact_rows(c, model, eq, neq, irn, jcn, val, gap)
    type(contact_t), intent(in) :: c
    type(model_t), intent(in) :: model
    integer, intent(in) :: eq(:), neq
    integer, allocatable, intent(out) :: irn(:), jcn(:)
    real(dp), allocatable, intent(out) :: val(:), gap(:)
    integer :: k, j, m, nd, d(max_row)
    real(dp) :: v(max_row)
    allocate (irn((max_row + 1)*c%nact), jcn((max_row + 1)*c%nact), val((max_row + 1)*c%nact), &
              gap(c%nact))
    m = 0
    do k = 1, c%nact
      gap(k) = c%act(k)%gap
      call constraint_row(c%act(k), model, d, v, nd)
      do j = 1, nd
        if (eq(d(j)) == 0) cycle   ! prescribed parameter: no column
        m = m + 1; irn(m) = neq + k; jcn(m) = eq(d(j)); val(m) = v(j)
      end do
      m = m + 1; irn(m) = neq + k; jcn(m) = neq + k; val(m) = 0
    end do
    irn = irn(1:m); jcn = jcn(1:m); val = val(1:m)
  end subroutine contact_rows

  !> f = C^T lambda (ndof): the multipliers' generalized force, fibres and thicknesses included
  subroutine contact_generalized_force(c, model, f)
    type(contact_t), intent(in) :: c
    type(model_t), intent(in) :: model
    real(dp), intent(out) :: f(:)
    integer :: k, nd, d(max_row)
    real(dp) :: v(max_row)
    f = 0
    do k = 1, c%nact
      call constraint_row(c%act(k), model, d, v, nd)
      f(d(1:nd)) = f(d(1:nd)) + c%act(k)%lambda*v(1:nd)
    end do
  end subroutine contact_generalized_force


  !> Total normal contact force (sum of the compressive multipliers).
  pure real(dp) function contact_force_total(c)
    type(contact_t), intent(in) :: c
    contact_force_total = -sum(c%act(1:c%nact)%lambda)
  end function contact_force_total

  !> Nodal contact force (3, nnode) on the bodies (both sides of a pair), -C^T lambda.
  pure subroutine contact_nodal_fields(c, model, force)
    type(contact_t), intent(in) :: c
    type(model_t), intent(in) :: model
    real(dp), intent(out) :: force(:, :)
    integer :: k, j, nodes(11), nn
    real(dp) :: w(11)
    force = 0
    do k = 1, c%nact
      call constraint_entries(c%act(k), model, nodes, w, nn)
      do j = 1, nn
        force(:, nodes(j)) = force(:, nodes(j)) - c%act(k)%lambda*w(j)*c%act(k)%n
      end do
    end do
  end subroutine contact_nodal_fields
end module casca_contact_rows
