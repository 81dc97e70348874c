!> One run of a deck as the time loop carries it from step to step (run_t), the limits its
!> watches judge by, and the exit codes (casca_run: the loop; casca_run_watch: its warnings)
module casca_run_state
  use casca_kinds, only: dp
  use casca_error, only: error_t
  use casca_deck, only: deck_t
  use casca_model, only: model_t
  use casca_assembly, only: assembly_t
  use casca_linear_system, only: linear_system_t
  use casca_newton, only: newton_opts_t, newton_report_t
  use casca_newmark, only: state_t
  use casca_time_scheme, only: scheme_t
  use casca_step_control, only: step_control_t
  use casca_accounting, only: balance_t
  use casca_output, only: output_t
  use casca_contact, only: contact_t
  implicit none
  private
  public :: run_t, least_t, progress_t
  public :: exit_ok, exit_input, exit_solver, exit_signal, cap_hold, easy_hold, newton_share, newton_floor, svk_limit

  integer, parameter :: exit_ok = 0, exit_input = 2, exit_solver = 3, exit_signal = 4
  !> with an error-controlled step: the energy's cap (run_t%dt_cap) doubles after this many of
  !> its lengths
  real(dp), parameter :: cap_hold = 20
  !> and after this many at a step that removed energy (where the energy does not limit it)
  real(dp), parameter :: easy_hold = 4
  !> under &run tolerance, Newton's tolerance is at most this share of the error asked for,
  !> and not below newton_floor (of the scene size: round-off's reach)
  real(dp), parameter :: newton_share = 1e-5_dp, newton_floor = 1e-12_dp
  !> Saint-Venant-Kirchhoff's least thickness stretch: its uniaxial compressive stress,
  !> E lambda (lambda^2 - 1)/2, is largest at lambda = 1/sqrt(3) (squeezed)
  real(dp), parameter :: svk_limit = 1/sqrt(3._dp)

  type :: least_t   !< the least of a stretch over the run's states: where and when
    real(dp) :: stretch = huge(1._dp), t = 0
    integer :: node = 0
    real(dp) :: t_past = -1   !< when it first went below svk_limit (-1: never)
  end type least_t

  !> statics: the tangent stiffness's negative pivots on what the contacts leave free, over
  !> the load steps (watch_stability): the most, the last load factor with none before they
  !> appeared, the first and the last with any (-1: none yet)
  type :: stability_t
    integer :: most = 0
    real(dp) :: t_before = -1, t_first = -1, t_last = -1
  end type stability_t

  type :: progress_t   !< where the last progress line was
    real(dp) :: wall = 0, t = 0
    integer :: step = 0, newton = 0
  end type progress_t

  !> One run of a deck: what it builds and what it carries from step to step
  type :: run_t
    type(deck_t) :: deck
    type(model_t) :: model
    type(assembly_t) :: asm
    type(linear_system_t), allocatable :: ls
    type(newton_opts_t) :: opts
    type(newton_report_t) :: rep
    type(state_t) :: st
    type(scheme_t) :: nm                        !< the time integration scheme
    type(step_control_t) :: sc                  !< steps by an error estimate (tol > 0)
    real(dp) :: dt_try = 0                      !< with sc: the next step's length
    logical :: onset = .false.                  !< with sc: a contact begins at this step's end or start
    !> with sc: the step up to a predicted contact failed and could not be halved (a sliver):
    !> the next is taken over that time instead, as fixed steps take it
    logical :: over_onset = .false.
    !> with sc: a step this long made too much energy with no contact active; shorter ones
    !> until a contact is active, the cap doubling after cap_hold of its lengths (in the
    !> checkpoint, with cap_since)
    real(dp) :: dt_cap = huge(1._dp)
    real(dp) :: cap_since = 0                   !< when dt_cap was set or last doubled
    !> the energy the last free step made (energy_accepted): a step may make back what the
    !> one before removed
    real(dp) :: made_last = 0
    logical :: floor_told = .false.             !< with sc: a step kept above the tolerance was told
    type(balance_t) :: bal, bal0                !< now, and at the start of the run
    !> the energy a step made (the remainder of the balance fell): the largest, when, and the
    !> contacts then; a run from t = 0 warns of it at its end (watch_energy)
    real(dp) :: rest_last = 0, made_max = 0, t_made = 0, dt_made = 0
    real(dp) :: dt_made_before = 0              !< the free step before it, when shorter (grown back)
    real(dp) :: e_scale = 0                     !< the largest energy the bodies held or the loads did
    integer :: made_contacts = 0
    !> the end of the last step with a contact active, and its value when the most was made
    !> (energy made a few steps after a release is the release's: warn_energy)
    real(dp) :: t_touch = 0, touch_made = 0
    integer :: made_between = 0                 !< of them, between bodies (not obstacles)
    !> bodies under gravity start held by their contacts (a = 0): the first step makes energy
    !> by that start (Newmark: (gamma^2/2 - beta) m g^2 dt^2), not by the contact; held_g2:
    !> their sum of m |g|^2 [kg m^2/s^4], so that m g^2 dt^2 of that step is not judged
    logical :: held_at_start = .false.
    real(dp) :: held_g2 = 0
    !> the least stretches the run's states reached, through the thickness and along the
    !> faces, where and when (watch_thickness, watch_faces)
    type(least_t) :: thick, face
    type(stability_t) :: stability
    !> the deepest a contact node sank into its target (the history's penetration column):
    !> how deep, which node, when (warn_sink)
    real(dp) :: sink = 0, t_sink = 0
    integer :: sink_node = 0
    type(output_t) :: out
    type(contact_t), allocatable :: contact     !< not allocated: no contact (absent below)
    type(error_t), allocatable :: err
    real(dp), allocatable :: fext(:), q0(:)     !< dead loads with gravity; reference state
    logical, allocatable :: frozen(:), idle(:)  !< idle bodies, left out of the equations
    integer, allocatable :: tracked(:)
    character(len=128), allocatable :: labels(:)
    character(len=:), allocatable :: dir, restart
    character(len=:), allocatable :: kept      !< the checkpoint a restart can go on from ('': none)
    real(dp) :: t0 = 0                          !< wall time at the start
    integer :: level = 0                        !< step cuts: dt / 2**level
    integer :: restart_step = -1, total_newton = 0, code = exit_ok
    logical :: quiet = .false.
    type(progress_t) :: last
  end type run_t
end module casca_run_state
