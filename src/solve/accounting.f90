!> Energy and momentum of a state: kinetic energy, strain energy, work of the dead loads,
!> linear and angular momentum, all from the constant consistent mass (no lumping).
module casca_accounting
  use casca_kinds, only: dp
  use casca_model, only: model_t, dof
  use casca_assembly, only: assembly_t, strain_energy
  use casca_newmark, only: state_t
  use casca_mpi, only: sum_all
  use casca_vectors, only: cross
  implicit none
  private
  public :: balance_t, account, gravity_load, balance_summary

  type :: balance_t
    real(dp) :: kinetic = 0, strain = 0, work = 0, total = 0
    real(dp) :: p(3) = 0, l(3) = 0
  end type balance_t

contains

  !> fext: the dead load; q0: the state where its work is zero.
  subroutine account(model, asm, st, fext, q0, bal)
    type(model_t), intent(in) :: model
    type(assembly_t), intent(in) :: asm
    type(state_t), intent(in) :: st
    real(dp), intent(in) :: fext(:), q0(:)
    type(balance_t), intent(out) :: bal
    real(dp) :: x(3, 20), v(3, 20), mv(3, 20), s(7)
    integer :: i, e, p

    bal%strain = strain_energy(model, asm, st%q)
    s = 0
    do i = 1, size(asm%owned)   ! every body: frozen ones move too
      e = asm%owned(i)
      call vectors(st%q, e, x)
      call vectors(st%qd, e, v)
      mv = matmul(v, model%emass(:, :, e))
      s(1) = s(1) + 0.5_dp*sum(v*mv)
      s(2:4) = s(2:4) + sum(mv(:, 1:10), dim=2)
      do p = 1, 20
        s(5:7) = s(5:7) + cross(x(:, p), mv(:, p))
      end do
    end do
    call sum_all(s)
    bal%kinetic = s(1); bal%p = s(2:4); bal%l = s(5:7)
    bal%work = dot_product(fext, st%q - q0)
    bal%total = bal%kinetic + bal%strain - bal%work
  contains
    !> the 20 vector parameters (Y^l, G^l) of element e from a full-length vector
    subroutine vectors(a, ee, w)
      real(dp), intent(in) :: a(:)
      integer, intent(in) :: ee
      real(dp), intent(out) :: w(3, 20)
      integer :: l, n
      do l = 1, 10
        n = model%conn(l, ee)
        w(:, l) = a(dof(n, 1):dof(n, 3))
        w(:, 10 + l) = a(dof(n, 4):dof(n, 6))
      end do
    end subroutine vectors
  end subroutine account

  !> Consistent nodal load of the body force rho*g: M applied to a uniform translation.
  subroutine gravity_load(model, f)
    type(model_t), intent(in) :: model
    real(dp), intent(out) :: f(:)
    integer :: e, l, n
    real(dp) :: m(20, 20)
    f = 0
    do e = 1, model%nelem
      m = model%emass(:, :, e)
      do l = 1, 10
        n = model%conn(l, e)
        f(dof(n, 1):dof(n, 3)) = f(dof(n, 1):dof(n, 3)) + model%gravity*sum(m(l, 1:10))
        f(dof(n, 4):dof(n, 6)) = f(dof(n, 4):dof(n, 6)) + model%gravity*sum(m(10 + l, 1:10))
      end do
    end do
  end subroutine gravity_load

  !> What the run kept, from the state first accounted (b0) to b: the drift of the linear
  !> momentum (of |p0|), of the angular momentum (of |L0|, or of |p0| times the scene size
  !> when L0 is smaller) and the change of the total energy (of E0). Contact forces keep both
  !> momenta; the Newmark step itself keeps the linear one only: its angular momentum
  !> drifts with dt (docs/method.md), which is why the figure is printed.
  function balance_summary(b0, b, length) result(line)
    type(balance_t), intent(in) :: b0, b
    real(dp), intent(in) :: length
    character(len=:), allocatable :: line
    character(len=200) :: buf
    real(dp) :: pref, lref
    pref = max(norm2(b0%p), tiny(1._dp))
    lref = max(norm2(b0%l), pref*length)
    write (buf, '(a,es8.1,a,es8.1,a,f8.5)') 'kept: linear momentum to ', norm2(b%p - b0%p)/pref, &
      ', angular momentum to ', norm2(b%l - b0%l)/lref, '; energy E/E0 = ', &
      b%total/max(abs(b0%total), tiny(1._dp))
    line = trim(buf)
  end function balance_summary
end module casca_accounting
