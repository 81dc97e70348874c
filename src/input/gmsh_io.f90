!> Gmsh MSH files (ASCII 4.1 and 2.2) holding 10-node cubic triangles (Gmsh element type 21).
!>
!> Gmsh's TRI10 node order is casca's order (see casca_mesh), so connectivity is copied as is.
!> Physical groups of points (type 15), lines (1, 8, 26) and triangles (21) become the
!> mesh's named node sets (mesh%sets): every node of their elements, in the mesh's numbering.
!> Any other surface element (quadrangles, triangles of other orders) is an error: skipped, it
!> would leave a part of the shell out unseen.
!> The reader loads the whole file into memory and walks it line by line, so that every error
!> names the file and the line where it was found; it never stops the program.
module casca_gmsh_io
  use casca_kinds, only: dp, i8
  use casca_error, only: error_t, fatal_error
  use casca_mesh, only: mesh_t, nen, node_set_t
  use casca_vectors, only: sort_index
  use casca_files, only: file_kind, kind_folder, kind_special, kind_regular, close_complete, &
                         delete_file, rename_file
  use, intrinsic :: iso_fortran_env, only: int64
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  implicit none
  private
  public :: read_gmsh, write_gmsh

  integer, parameter :: tri10_type = 21
  !> Gmsh's triangles and quadrangles of orders 1 to 4 (MSH 2.2 gives no dimension)
  integer, parameter :: surface_types(*) = [2, 3, 9, 10, 16, 20, 21, 22, 23, 24, 36, 37, 39, 40, 41]
  real(dp), parameter :: max_coordinate = 1e15_dp   !< [m]: far beyond any scene, far below overflow
  character(len=*), parameter :: coordinate_rule = &
    'node coordinates must be finite numbers of size below 1e15 m'

  !> Position in the in-memory file: the next line starts at buf(pos:); `line` is the number of
  !> the line last returned (0 before the first).
  type :: cursor_t
    character(len=:), allocatable :: path
    character(len=:), allocatable :: buf
    integer :: pos = 1
    integer :: line = 0
  end type cursor_t

  !> What was read, before node tags are resolved (Gmsh tags may be sparse and unordered).
  type :: raw_t
    integer :: nnode = 0
    integer(i8), allocatable :: node_tag(:)
    integer, allocatable :: node_line(:)
    real(dp), allocatable :: x(:, :)
    integer :: nelem = 0
    integer(i8), allocatable :: elem_nodes(:, :)
    integer, allocatable :: elem_line(:)
    !> $PhysicalNames: dimension, tag, name
    integer :: nnames = 0
    integer, allocatable :: name_dim(:), name_tag(:)
    character(len=256), allocatable :: name_text(:)
    !> MSH 4.1 $Entities: (dimension, entity tag, physical tag) for each physical tag of an entity
    integer :: nent = 0
    integer, allocatable :: ent(:, :)
    !> nodes of physical groups: (dimension, physical tag, node tag, line of the element)
    integer :: nmember = 0
    integer(i8), allocatable :: member(:, :)
    !> surface elements that are not 10-node triangles: how many, the first's type and line
    integer :: nother = 0, other_type = 0, other_line = 0
  end type raw_t

contains

  !> Read the 10-node triangles of a Gmsh MSH 4.1 or 2.2 ASCII file. Points, lines and volumes
  !> are skipped, other surface elements refused; nodes not used by a triangle are dropped
  !> and the rest renumbered 1..nnode in ascending Gmsh tag order. mesh%normal is left with
  !> size (3, 0): a file has no exact normals.
  subroutine read_gmsh(path, mesh, err)
    character(len=*), intent(in) :: path
    type(mesh_t), intent(out) :: mesh
    type(error_t), allocatable, intent(out) :: err
    type(cursor_t) :: cur
    type(raw_t) :: raw
    character(len=:), allocatable :: section
    integer :: s, e, version, section_line
    logical :: have_format, have_nodes, have_elements
    character(len=160) :: what

    call load_file(path, cur, err)
    if (allocated(err)) return
    have_format = .false.
    have_nodes = .false.
    have_elements = .false.
    version = 0

    do
      if (.not. next_line(cur, s, e)) exit
      if (e < s) cycle                       ! tolerate blank lines between sections
      if (cur%buf(s:s) /= '$') then
        call fail(err, cur, "expected a section header such as $Nodes, found '" // clip(cur%buf(s:e)) // "'")
        return
      end if
      section = cur%buf(s + 1:e)
      section_line = cur%line
      if (.not. have_format .and. section /= 'MeshFormat') then
        call fail(err, cur, "not a Gmsh MSH file: the first section must be $MeshFormat, found '" &
                  // clip(cur%buf(s:e)) // "'")
        return
      end if
      select case (section)
      case ('MeshFormat')
        call read_format(cur, version, err)
        have_format = .true.
      case ('Nodes')
        if (have_nodes) then
          call fail(err, cur, "second $Nodes section (only one is supported)")
          return
        end if
        if (version == 41) then
          call read_nodes_v41(cur, raw, err)
        else
          call read_nodes_v22(cur, raw, err)
        end if
        have_nodes = .true.
      case ('Elements')
        if (have_elements) then
          call fail(err, cur, "second $Elements section (only one is supported)")
          return
        end if
        if (version == 41) then
          call read_elements_v41(cur, raw, err)
        else
          call read_elements_v22(cur, raw, err)
        end if
        have_elements = .true.
      case ('PhysicalNames')
        call read_physical_names(cur, raw, err)
      case ('Entities')
        if (version == 41) then
          call read_entities_v41(cur, raw, err)
        else
          call skip_section(cur, section, section_line, err)
        end if
      case default
        ! $PartitionedEntities, $NodeData, ...: not needed here.
        call skip_section(cur, section, section_line, err)
      end select
      if (allocated(err)) return
    end do

    if (.not. have_format) then
      call fail(err, cur, "empty file: no $MeshFormat section")
    else if (.not. have_nodes) then
      call fail(err, cur, "end of file reached without a $Nodes section")
    else if (.not. have_elements) then
      call fail(err, cur, "end of file reached without an $Elements section")
    else if (raw%nother > 0) then   ! (a part of the shell would be left out unseen)
      if (raw%nother == 1) then
        write (what, '(a, i0, a, i0)') '1 surface element that is not a 10-node triangle (Gmsh type ', &
          raw%other_type, ', line ', raw%other_line
      else
        write (what, '(i0, a, i0, a, i0)') raw%nother, ' surface elements that are not 10-node ' &
          // 'triangles (the first of Gmsh type ', raw%other_type, ', line ', raw%other_line
      end if
      call fail(err, cur, trim(what) // '); casca reads only type 21: mesh every surface with ' &
                // 'Mesh.ElementOrder=3, Mesh.SecondOrderIncomplete=0 and no recombination into quadrangles')
    else if (raw%nelem == 0) then
      call fail(err, cur, "no 10-node triangles (Gmsh element type 21) in the file; mesh with " &
                // "Mesh.ElementOrder=3 and Mesh.SecondOrderIncomplete=0")
    end if
    if (allocated(err)) return
    call build_mesh(cur, raw, mesh, err)
  end subroutine read_gmsh

  !> Write mesh as Gmsh MSH 4.1 ASCII: one surface entity (tag 1) holding every node (tags
  !> 1..nnode) and every element as a type-21 triangle (tags 1..nelem).
  subroutine write_gmsh(path, mesh, err)
    character(len=*), intent(in) :: path
    type(mesh_t), intent(in) :: mesh
    type(error_t), allocatable, intent(out) :: err
    integer :: u, ios, i, nblock
    character(len=512) :: msg
    real(dp) :: lo(3), hi(3)

    if (.not. allocated(mesh%x) .or. .not. allocated(mesh%conn)) then
      call fatal_error(err, path // ": write_gmsh: mesh has no coordinates or connectivity")
      return
    end if
    if (size(mesh%x, 1) /= 3 .or. size(mesh%x, 2) /= mesh%nnode .or. size(mesh%conn, 1) /= nen &
        .or. size(mesh%conn, 2) /= mesh%nelem) then
      call fatal_error(err, path // ": write_gmsh: mesh array shapes disagree with nnode/nelem")
      return
    end if
    if (mesh%nelem > 0) then
      if (minval(mesh%conn) < 1 .or. maxval(mesh%conn) > mesh%nnode) then
        call fatal_error(err, path // ": write_gmsh: connectivity refers to a node outside 1..nnode")
        return
      end if
    end if

    if (.not. all(sound(mesh%x))) then   ! (read_gmsh would refuse the file)
      call fatal_error(err, path//": "//coordinate_rule)
      return
    end if

    ! written to path.part, renamed when complete (stream: close_complete checks the size)
    open (newunit=u, file=path//'.part', status='replace', action='write', form='formatted', &
          access='stream', iostat=ios, iomsg=msg)
    if (ios /= 0) then
      call fatal_error(err, path // ": cannot open for writing: " // trim(msg))
      return
    end if
    if (mesh%nnode > 0) then
      lo = minval(mesh%x, dim=2)
      hi = maxval(mesh%x, dim=2)
    else
      lo = 0.0_dp
      hi = 0.0_dp
    end if
    nblock = merge(1, 0, mesh%nnode > 0)

    write (u, '(a)', iostat=ios, iomsg=msg) '$MeshFormat'
    if (ios == 0) write (u, '(a)', iostat=ios, iomsg=msg) '4.1 0 8'
    if (ios == 0) write (u, '(a)', iostat=ios, iomsg=msg) '$EndMeshFormat'
    ! Entities: 0 points, 0 curves, 1 surface (bounding box, no physical tags, no bounding curves).
    if (ios == 0) write (u, '(a)', iostat=ios, iomsg=msg) '$Entities'
    if (ios == 0) write (u, '(a)', iostat=ios, iomsg=msg) '0 0 1 0'
    if (ios == 0) write (u, '(a,6(1x,es24.16e3),a)', iostat=ios, iomsg=msg) '1', lo, hi, ' 0 0'
    if (ios == 0) write (u, '(a)', iostat=ios, iomsg=msg) '$EndEntities'
    if (ios == 0) write (u, '(a)', iostat=ios, iomsg=msg) '$Nodes'
    if (ios == 0) write (u, '(i0,3(1x,i0))', iostat=ios, iomsg=msg) nblock, mesh%nnode, min(1, mesh%nnode), mesh%nnode
    if (ios == 0 .and. nblock == 1) write (u, '(a,1x,i0)', iostat=ios, iomsg=msg) '2 1 0', mesh%nnode
    do i = 1, mesh%nnode
      if (ios /= 0) exit
      write (u, '(i0)', iostat=ios, iomsg=msg) i
    end do
    ! 17 significant digits: coordinates survive a write/read round trip bit for bit.
    do i = 1, mesh%nnode
      if (ios /= 0) exit
      write (u, '(es24.16e3,2(1x,es24.16e3))', iostat=ios, iomsg=msg) mesh%x(:, i)
    end do
    if (ios == 0) write (u, '(a)', iostat=ios, iomsg=msg) '$EndNodes'
    nblock = merge(1, 0, mesh%nelem > 0)
    if (ios == 0) write (u, '(a)', iostat=ios, iomsg=msg) '$Elements'
    if (ios == 0) write (u, '(i0,3(1x,i0))', iostat=ios, iomsg=msg) nblock, mesh%nelem, min(1, mesh%nelem), mesh%nelem
    if (ios == 0 .and. nblock == 1) write (u, '(a,1x,i0,1x,i0)', iostat=ios, iomsg=msg) '2 1', tri10_type, mesh%nelem
    do i = 1, mesh%nelem
      if (ios /= 0) exit
      write (u, '(i0,10(1x,i0))', iostat=ios, iomsg=msg) i, mesh%conn(:, i)
    end do
    if (ios == 0) write (u, '(a)', iostat=ios, iomsg=msg) '$EndElements'
    if (ios /= 0) then
      call fatal_error(err, path // ": write failed: " // trim(msg))
      close (u, status='delete', iostat=ios)
      return
    end if
    if (.not. close_complete(u, path//'.part')) then
      call delete_file(path//'.part')
      call fatal_error(err, path // ": write failed (is the disk full?)")
    else if (.not. rename_file(path//'.part', path)) then
      call delete_file(path//'.part')
      call fatal_error(err, path // ": cannot rename " // path // ".part onto it")
    end if
  end subroutine write_gmsh

  ! ---------------------------------------------------------------------------------------------
  ! Sections

  !> "$MeshFormat": version, file-type (0 = ASCII), data-size; then "$EndMeshFormat".
  subroutine read_format(cur, version, err)
    type(cursor_t), intent(inout) :: cur
    integer, intent(out) :: version
    type(error_t), allocatable, intent(out) :: err
    character(len=32) :: vstr
    integer :: s, e, ios, file_type, data_size

    version = 0
    if (.not. need_line(cur, s, e, "$MeshFormat", err)) return
    read (cur%buf(s:e), *, iostat=ios) vstr, file_type, data_size
    if (ios /= 0) then
      call fail(err, cur, "expected 'version file-type data-size' in $MeshFormat, found '" // clip(cur%buf(s:e)) // "'")
      return
    end if
    select case (trim(vstr))
    case ('4.1')
      version = 41
    case ('2.2')
      version = 22
    case default
      call fail(err, cur, "unsupported MSH version " // trim(vstr) // " (casca reads MSH 4.1 and 2.2 ASCII; " &
                // "set Mesh.MshFileVersion)")
      return
    end select
    if (file_type /= 0) then
      call fail(err, cur, "binary MSH file (file-type 1) is not supported; save it with Mesh.Binary=0")
      return
    end if
    call expect_end(cur, 'MeshFormat', err)
  end subroutine read_format

  !> MSH 4.1 $Nodes: "numEntityBlocks numNodes minTag maxTag", then per block
  !> "entityDim entityTag parametric numNodesInBlock", the block's tags (one a line), then its
  !> coordinates "x y z [u [v [w]]]" (one a line).
  subroutine read_nodes_v41(cur, raw, err)
    type(cursor_t), intent(inout) :: cur
    type(raw_t), intent(inout) :: raw
    type(error_t), allocatable, intent(out) :: err
    integer(i8) :: nblocks, nnodes, min_tag, max_tag, tag
    integer :: s, e, ios, ib, k, first, dim, etag, param, nin
    character(len=16) :: what

    if (.not. need_line(cur, s, e, "$Nodes", err)) return
    read (cur%buf(s:e), *, iostat=ios) nblocks, nnodes, min_tag, max_tag
    if (ios /= 0) then
      call fail(err, cur, "expected 4 integers in $Nodes block header, found '" // clip(cur%buf(s:e)) // "'")
      return
    end if
    if (nblocks < 0 .or. nblocks > huge(1) .or. nnodes < 0 .or. nnodes > huge(1)) then
      call fail(err, cur, "invalid counts in $Nodes block header")
      return
    end if
    call alloc_nodes(cur, raw, int(nnodes), err)
    if (allocated(err)) return

    do ib = 1, int(nblocks)
      if (.not. need_line(cur, s, e, "$Nodes", err)) return
      read (cur%buf(s:e), *, iostat=ios) dim, etag, param, nin
      if (ios /= 0) then
        call fail(err, cur, "expected 4 integers in $Nodes entity block header " &
                  // "(entityDim entityTag parametric numNodesInBlock), found '" // clip(cur%buf(s:e)) // "'")
        return
      end if
      if (nin < 0 .or. raw%nnode + nin > size(raw%node_tag)) then
        write (what, '(i0)') nnodes
        call fail(err, cur, "node blocks hold more nodes than the " // trim(what) // " announced in the $Nodes header")
        return
      end if
      first = raw%nnode
      do k = 1, nin
        if (.not. need_line(cur, s, e, "$Nodes", err)) return
        read (cur%buf(s:e), *, iostat=ios) tag
        if (ios /= 0) then
          call fail(err, cur, "expected a node tag, found '" // clip(cur%buf(s:e)) // "'")
          return
        end if
        raw%node_tag(first + k) = tag
        raw%node_line(first + k) = cur%line
      end do
      do k = 1, nin
        if (.not. need_line(cur, s, e, "$Nodes", err)) return
        read (cur%buf(s:e), *, iostat=ios) raw%x(:, first + k)
        if (ios /= 0) then
          call fail(err, cur, "expected 3 node coordinates 'x y z', found '" // clip(cur%buf(s:e)) // "'")
          return
        end if
        call check_coordinates(cur, raw%x(:, first + k), err)
        if (allocated(err)) return
      end do
      raw%nnode = first + nin
    end do
    if (raw%nnode /= nnodes) then
      call fail(err, cur, "fewer nodes in the blocks than announced in the $Nodes header")
      return
    end if
    call expect_end(cur, 'Nodes', err)
  end subroutine read_nodes_v41

  !> MSH 2.2 $Nodes: "number-of-nodes", then "tag x y z" lines.
  subroutine read_nodes_v22(cur, raw, err)
    type(cursor_t), intent(inout) :: cur
    type(raw_t), intent(inout) :: raw
    type(error_t), allocatable, intent(out) :: err
    integer :: s, e, ios, k, n

    if (.not. need_line(cur, s, e, "$Nodes", err)) return
    read (cur%buf(s:e), *, iostat=ios) n
    if (ios /= 0 .or. n < 0) then
      call fail(err, cur, "expected the number of nodes in $Nodes, found '" // clip(cur%buf(s:e)) // "'")
      return
    end if
    call alloc_nodes(cur, raw, n, err)
    if (allocated(err)) return
    do k = 1, n
      if (.not. need_line(cur, s, e, "$Nodes", err)) return
      read (cur%buf(s:e), *, iostat=ios) raw%node_tag(k), raw%x(:, k)
      if (ios /= 0) then
        call fail(err, cur, "expected 'node-tag x y z', found '" // clip(cur%buf(s:e)) // "'")
        return
      end if
      call check_coordinates(cur, raw%x(:, k), err)
      if (allocated(err)) return
      raw%node_line(k) = cur%line
    end do
    raw%nnode = n
    call expect_end(cur, 'Nodes', err)
  end subroutine read_nodes_v22

  !> MSH 4.1 $Elements: "numEntityBlocks numElements minTag maxTag", then per block
  !> "entityDim entityTag elementType numElementsInBlock" and one "tag node..." line per element.
  subroutine read_elements_v41(cur, raw, err)
    type(cursor_t), intent(inout) :: cur
    type(raw_t), intent(inout) :: raw
    type(error_t), allocatable, intent(out) :: err
    integer(i8) :: nblocks, nelems, min_tag, max_tag, tag, enodes(nen)
    integer :: s, e, ios, ib, k, dim, etag, etype, nin, nn, i
    integer, allocatable :: phys(:)
    character(len=16) :: what

    if (.not. need_line(cur, s, e, "$Elements", err)) return
    read (cur%buf(s:e), *, iostat=ios) nblocks, nelems, min_tag, max_tag
    if (ios /= 0) then
      call fail(err, cur, "expected 4 integers in $Elements block header, found '" // clip(cur%buf(s:e)) // "'")
      return
    end if
    if (nblocks < 0 .or. nblocks > huge(1) .or. nelems < 0 .or. nelems > huge(1)) then
      call fail(err, cur, "invalid counts in $Elements block header")
      return
    end if
    call alloc_elems(cur, raw, int(nelems), err)
    if (allocated(err)) return

    do ib = 1, int(nblocks)
      if (.not. need_line(cur, s, e, "$Elements", err)) return
      read (cur%buf(s:e), *, iostat=ios) dim, etag, etype, nin
      if (ios /= 0 .or. nin < 0) then
        call fail(err, cur, "expected 4 integers in $Elements entity block header " &
                  // "(entityDim entityTag elementType numElementsInBlock), found '" // clip(cur%buf(s:e)) // "'")
        return
      end if
      if (raw%nent > 0) then
        phys = pack(raw%ent(3, 1:raw%nent), raw%ent(1, 1:raw%nent) == dim .and. &
                    raw%ent(2, 1:raw%nent) == etag)
      else
        phys = [integer ::]   ! (no $Entities section)
      end if
      nn = nodes_of_type(etype)
      if (dim == 2 .and. etype /= tri10_type .and. nin > 0) call other_surface(raw, etype, cur%line + 1, nin)
      do k = 1, nin
        if (.not. need_line(cur, s, e, "$Elements", err)) return
        if (etype == tri10_type) then
          if (raw%nelem >= size(raw%elem_line)) then
            call fail(err, cur, "more elements than announced in the $Elements header")
            return
          end if
          read (cur%buf(s:e), *, iostat=ios) tag, raw%elem_nodes(:, raw%nelem + 1)
          if (ios /= 0) then
            call fail(err, cur, "expected 11 integers 'element-tag node1 ... node10' for a type-21 triangle, found '" &
                      // clip(cur%buf(s:e)) // "'")
            return
          end if
          raw%nelem = raw%nelem + 1
          raw%elem_line(raw%nelem) = cur%line
          enodes(1:nn) = raw%elem_nodes(:, raw%nelem)
        else if (nn > 0 .and. size(phys) > 0) then
          read (cur%buf(s:e), *, iostat=ios) tag, enodes(1:nn)
          if (ios /= 0) then
            write (what, '(i0)') nn + 1
            call fail(err, cur, "expected " // trim(what) // " integers 'element-tag node...' for an element of a " &
                      // "physical group, found '" // clip(cur%buf(s:e)) // "'")
            return
          end if
        else
          cycle     ! other element types, elements of no physical group: not casca's
        end if
        do i = 1, size(phys)
          call add_members(raw, dim, phys(i), enodes(1:nn), cur%line)
        end do
      end do
    end do
    call expect_end(cur, 'Elements', err)
  end subroutine read_elements_v41

  !> MSH 2.2 $Elements: "number-of-elements", then "tag type ntags tag... node..." lines.
  subroutine read_elements_v22(cur, raw, err)
    type(cursor_t), intent(inout) :: cur
    type(raw_t), intent(inout) :: raw
    type(error_t), allocatable, intent(out) :: err
    integer :: s, e, ios, k, n, i, tag, etype, ntags, nn
    integer :: tags(64)
    integer(i8) :: enodes(nen)
    character(len=16) :: what

    if (.not. need_line(cur, s, e, "$Elements", err)) return
    read (cur%buf(s:e), *, iostat=ios) n
    if (ios /= 0 .or. n < 0) then
      call fail(err, cur, "expected the number of elements in $Elements, found '" // clip(cur%buf(s:e)) // "'")
      return
    end if
    call alloc_elems(cur, raw, n, err)
    if (allocated(err)) return
    do k = 1, n
      if (.not. need_line(cur, s, e, "$Elements", err)) return
      read (cur%buf(s:e), *, iostat=ios) tag, etype, ntags
      if (ios /= 0) then
        call fail(err, cur, "expected 'element-tag type number-of-tags ...', found '" // clip(cur%buf(s:e)) // "'")
        return
      end if
      if (etype /= tri10_type .and. any(etype == surface_types)) call other_surface(raw, etype, cur%line, 1)
      nn = nodes_of_type(etype)
      if (nn == 0) cycle                   ! volumes, quadrangles, ...: not casca's
      if (ntags < 0 .or. ntags > size(tags)) then
        call fail(err, cur, "invalid number of element tags")
        return
      end if
      if (etype == tri10_type) then
        read (cur%buf(s:e), *, iostat=ios) tag, etype, ntags, (tags(i), i=1, ntags), raw%elem_nodes(:, raw%nelem + 1)
        if (ios /= 0) then
          call fail(err, cur, "expected 10 node tags after the element tags of a type-21 triangle, found '" &
                    // clip(cur%buf(s:e)) // "'")
          return
        end if
        raw%nelem = raw%nelem + 1
        raw%elem_line(raw%nelem) = cur%line
        enodes = raw%elem_nodes(:, raw%nelem)
      else
        if (ntags < 1) cycle               ! (the first tag is the physical group)
        read (cur%buf(s:e), *, iostat=ios) tag, etype, ntags, (tags(i), i=1, ntags), enodes(1:nn)
        if (ios /= 0) then
          write (what, '(i0)') nn
          call fail(err, cur, "expected " // trim(what) // " node tags after the element tags, found '" &
                    // clip(cur%buf(s:e)) // "'")
          return
        end if
      end if
      if (ntags >= 1) then
        if (tags(1) /= 0) call add_members(raw, dim_of_type(etype), tags(1), enodes(1:nn), cur%line)
      end if
    end do
    call expect_end(cur, 'Elements', err)
  end subroutine read_elements_v22

  !> "$PhysicalNames": the number of names, then 'dimension tag "name"' lines.
  subroutine read_physical_names(cur, raw, err)
    type(cursor_t), intent(inout) :: cur
    type(raw_t), intent(inout) :: raw
    type(error_t), allocatable, intent(out) :: err
    integer :: s, e, ios, k, n, q1, q2
    if (.not. need_line(cur, s, e, "$PhysicalNames", err)) return
    read (cur%buf(s:e), *, iostat=ios) n
    if (ios /= 0 .or. n < 0) then
      call fail(err, cur, "expected the number of names in $PhysicalNames, found '" // clip(cur%buf(s:e)) // "'")
      return
    end if
    allocate (raw%name_dim(n), raw%name_tag(n), raw%name_text(n))
    do k = 1, n
      ! (not need_line: a name may hold a ',' or '/')
      if (.not. next_line(cur, s, e)) then
        cur%line = cur%line + 1
        call fail(err, cur, "unexpected end of file inside $PhysicalNames (file truncated?)")
        return
      end if
      q1 = index(cur%buf(s:e), '"')
      q2 = index(cur%buf(s:e), '"', back=.true.)
      ios = 1
      if (q2 > q1 + 1) read (cur%buf(s:s + q1 - 2), *, iostat=ios) raw%name_dim(k), raw%name_tag(k)
      if (ios /= 0) then
        call fail(err, cur, "expected 'dimension tag ""name""' in $PhysicalNames, found '" // clip(cur%buf(s:e)) // "'")
        return
      end if
      raw%name_text(k) = cur%buf(s + q1:s + q2 - 2)
    end do
    raw%nnames = n
    call expect_end(cur, 'PhysicalNames', err)
  end subroutine read_physical_names

  !> MSH 4.1 "$Entities": "numPoints numCurves numSurfaces numVolumes", then one line per
  !> entity: points "tag x y z numPhysicalTags physicalTag...", the others "tag minX minY minZ
  !> maxX maxY maxZ numPhysicalTags physicalTag... numBounding boundingTag...". Only the
  !> physical tags are kept.
  subroutine read_entities_v41(cur, raw, err)
    type(cursor_t), intent(inout) :: cur
    type(raw_t), intent(inout) :: raw
    type(error_t), allocatable, intent(out) :: err
    integer :: s, e, ios, counts(4), dim, k, tag, np, nbox, i
    real(dp) :: box(6)
    integer :: phys(256)
    if (.not. need_line(cur, s, e, "$Entities", err)) return
    read (cur%buf(s:e), *, iostat=ios) counts
    if (ios /= 0 .or. any(counts < 0)) then
      call fail(err, cur, "expected 4 counts in $Entities, found '" // clip(cur%buf(s:e)) // "'")
      return
    end if
    allocate (raw%ent(3, 16))
    do dim = 0, 3
      nbox = merge(3, 6, dim == 0)
      do k = 1, counts(dim + 1)
        if (.not. need_line(cur, s, e, "$Entities", err)) return
        read (cur%buf(s:e), *, iostat=ios) tag, box(1:nbox), np
        if (ios == 0 .and. (np < 0 .or. np > size(phys))) ios = 1
        if (ios == 0) read (cur%buf(s:e), *, iostat=ios) tag, box(1:nbox), np, phys(1:np)
        if (ios /= 0) then
          call fail(err, cur, "expected an entity 'tag bounds... numPhysicalTags physicalTag...', found '" &
                    // clip(cur%buf(s:e)) // "'")
          return
        end if
        do i = 1, np
          if (raw%nent == size(raw%ent, 2)) raw%ent = reshape(raw%ent, [3, 2*raw%nent], pad=[0])
          raw%nent = raw%nent + 1
          raw%ent(:, raw%nent) = [dim, tag, abs(phys(i))]   ! (a sign is an orientation)
        end do
      end do
    end do
    call expect_end(cur, 'Entities', err)
  end subroutine read_entities_v41

  !> Record the nodes of an element of physical group (dim, phys), found at line.
  subroutine add_members(raw, dim, phys, nodes, line)
    type(raw_t), intent(inout) :: raw
    integer, intent(in) :: dim, phys, line
    integer(i8), intent(in) :: nodes(:)
    integer :: k
    if (.not. allocated(raw%member)) allocate (raw%member(4, 64))
    do k = 1, size(nodes)
      if (raw%nmember == size(raw%member, 2)) &
        raw%member = reshape(raw%member, [4, 2*raw%nmember], pad=[0_i8])
      raw%nmember = raw%nmember + 1
      raw%member(:, raw%nmember) = [int(dim, i8), int(phys, i8), nodes(k), int(line, i8)]
    end do
  end subroutine add_members

  !> Nodes of the element types a physical group may hold: point, 2-, 3- and 4-node lines,
  !> 3- and 10-node triangles; 0 for the others.
  pure integer function nodes_of_type(etype)
    integer, intent(in) :: etype
    select case (etype)
    case (15); nodes_of_type = 1
    case (1); nodes_of_type = 2
    case (8); nodes_of_type = 3
    case (26); nodes_of_type = 4
    case (2); nodes_of_type = 3
    case (tri10_type); nodes_of_type = nen
    case default; nodes_of_type = 0
    end select
  end function nodes_of_type

  !> n surface elements of Gmsh type etype, not casca's, from line
  subroutine other_surface(raw, etype, line, n)
    type(raw_t), intent(inout) :: raw
    integer, intent(in) :: etype, line, n
    if (raw%nother == 0) then
      raw%other_type = etype; raw%other_line = line
    end if
    raw%nother = raw%nother + n
  end subroutine other_surface

  pure integer function dim_of_type(etype)
    integer, intent(in) :: etype
    select case (etype)
    case (15); dim_of_type = 0
    case (1, 8, 26); dim_of_type = 1
    case default; dim_of_type = 2
    end select
  end function dim_of_type

  !> Skip an unneeded section up to its "$End" line.
  subroutine skip_section(cur, section, start_line, err)
    type(cursor_t), intent(inout) :: cur
    character(len=*), intent(in) :: section
    integer, intent(in) :: start_line
    type(error_t), allocatable, intent(out) :: err
    integer :: s, e
    character(len=16) :: ln
    do
      if (.not. next_line(cur, s, e)) then
        write (ln, '(i0)') start_line
        call fail(err, cur, "unexpected end of file: $" // section // " (opened at line " // trim(ln) &
                  // ") has no $End" // section)
        return
      end if
      if (cur%buf(s:e) == '$End' // section) return
    end do
  end subroutine skip_section

  !> Resolve node tags, keep only nodes used by triangles, number them by ascending tag.
  subroutine build_mesh(cur, raw, mesh, err)
    type(cursor_t), intent(inout) :: cur
    type(raw_t), intent(in) :: raw
    type(mesh_t), intent(out) :: mesh
    type(error_t), allocatable, intent(out) :: err
    integer, allocatable :: order(:), new_id(:), conn_sorted(:, :)
    integer(i8), allocatable :: sorted_tag(:)
    integer :: i, k, ie, pos, n_used
    character(len=24) :: tagstr

    call sort_index(real(raw%node_tag(1:raw%nnode), dp), order)   ! (tags far below 2^53: exact)
    sorted_tag = raw%node_tag(order)
    do i = 2, raw%nnode
      if (sorted_tag(i) == sorted_tag(i - 1)) then
        write (tagstr, '(i0)') sorted_tag(i)
        cur%line = max(raw%node_line(order(i)), raw%node_line(order(i - 1)))
        call fail(err, cur, "node tag " // trim(tagstr) // " is defined twice")
        return
      end if
    end do

    ! conn_sorted holds positions in the sorted tag list.
    allocate (conn_sorted(nen, raw%nelem), new_id(raw%nnode))
    new_id = 0
    do ie = 1, raw%nelem
      do k = 1, nen
        pos = find_sorted(sorted_tag, raw%elem_nodes(k, ie))
        if (pos == 0) then
          write (tagstr, '(i0)') raw%elem_nodes(k, ie)
          cur%line = raw%elem_line(ie)
          call fail(err, cur, "element refers to node tag " // trim(tagstr) // ", which is not defined in $Nodes")
          return
        end if
        conn_sorted(k, ie) = pos
        new_id(pos) = 1
      end do
    end do

    n_used = 0
    do i = 1, raw%nnode
      if (new_id(i) /= 0) then
        n_used = n_used + 1
        new_id(i) = n_used
      end if
    end do

    mesh%nnode = n_used
    mesh%nelem = raw%nelem
    allocate (mesh%x(3, n_used), mesh%normal(3, 0), mesh%conn(nen, raw%nelem))
    do i = 1, raw%nnode
      if (new_id(i) /= 0) mesh%x(:, new_id(i)) = raw%x(:, order(i))
    end do
    do ie = 1, raw%nelem
      mesh%conn(:, ie) = new_id(conn_sorted(:, ie))
    end do
    call build_sets(cur, raw, sorted_tag, new_id, mesh, err)
  end subroutine build_mesh

  !> The physical groups as node sets: named by $PhysicalNames (else by their tag), groups of
  !> one name merged, nodes in the mesh's numbering. A node that no 10-node triangle uses is
  !> an error: the group would select nothing casca knows.
  subroutine build_sets(cur, raw, sorted_tag, new_id, mesh, err)
    type(cursor_t), intent(inout) :: cur
    type(raw_t), intent(in) :: raw
    integer(i8), intent(in) :: sorted_tag(:)
    integer, intent(in) :: new_id(:)
    type(mesh_t), intent(inout) :: mesh
    type(error_t), allocatable, intent(out) :: err
    character(len=256), allocatable :: names(:)
    character(len=24) :: tagstr
    logical, allocatable :: in_set(:), same(:)
    integer, allocatable :: gdim(:), gtag(:), gidx(:)
    type(node_set_t), allocatable :: grown(:)
    integer :: m, j, g, ng, pos

    ! the distinct groups (dimension, tag): few, while a surface group has 10 entries a triangle
    allocate (gdim(0), gtag(0), gidx(raw%nmember), mesh%sets(0))
    ng = 0
    do m = 1, raw%nmember
      g = 0
      do j = 1, ng
        if (gdim(j) == raw%member(1, m) .and. gtag(j) == raw%member(2, m)) then
          g = j; exit
        end if
      end do
      if (g == 0) then
        gdim = [gdim, int(raw%member(1, m))]; gtag = [gtag, int(raw%member(2, m))]
        ng = ng + 1; g = ng
      end if
      gidx(m) = g
    end do
    allocate (names(ng), in_set(mesh%nnode))
    do g = 1, ng
      names(g) = group_name(gdim(g), gtag(g))
    end do
    do g = 1, ng
      if (any(names(1:g - 1) == names(g))) cycle   ! (its name's set is built)
      same = names == names(g)
      in_set = .false.
      do m = 1, raw%nmember
        if (.not. same(gidx(m))) cycle
        pos = find_sorted(sorted_tag, raw%member(3, m))
        if (pos > 0) then
          if (new_id(pos) > 0) then
            in_set(new_id(pos)) = .true.
            cycle
          end if
        end if
        write (tagstr, '(i0)') raw%member(3, m)
        cur%line = int(raw%member(4, m))
        if (pos == 0) then
          call fail(err, cur, "physical group '" // trim(names(g)) // "': element refers to node tag " // &
                    trim(tagstr) // ", which is not defined in $Nodes")
        else
          call fail(err, cur, "physical group '" // trim(names(g)) // "': node tag " // trim(tagstr) // &
                    " is on no 10-node triangle")
        end if
        return
      end do
      ! (grown by hand: gfortran garbles a deferred-length name in an array constructor)
      allocate (grown(size(mesh%sets) + 1))
      do j = 1, size(mesh%sets)
        call move_alloc(mesh%sets(j)%name, grown(j)%name)
        call move_alloc(mesh%sets(j)%nodes, grown(j)%nodes)
      end do
      grown(size(grown))%name = trim(names(g))
      grown(size(grown))%nodes = pack([(j, j=1, mesh%nnode)], in_set)
      call move_alloc(grown, mesh%sets)
    end do
  contains
    function group_name(dim, tag) result(r)
      integer, intent(in) :: dim, tag
      character(len=256) :: r
      integer :: i
      do i = 1, raw%nnames
        if (raw%name_dim(i) == dim .and. raw%name_tag(i) == tag) then
          r = raw%name_text(i); return
        end if
      end do
      write (r, '(i0)') tag
    end function group_name
  end subroutine build_sets

  ! ---------------------------------------------------------------------------------------------
  ! Helpers

  !> Coordinates on the current line must be finite and below max_coordinate in size (a NaN,
  !> an Inf or 1e308 would pass every later check)
  subroutine check_coordinates(cur, x, err)
    type(cursor_t), intent(inout) :: cur
    real(dp), intent(in) :: x(3)
    type(error_t), allocatable, intent(out) :: err
    if (.not. all(sound(x))) call fail(err, cur, coordinate_rule)
  end subroutine check_coordinates

  !> a coordinate read_gmsh accepts
  elemental logical function sound(x)
    real(dp), intent(in) :: x
    sound = ieee_is_finite(x) .and. abs(x) <= max_coordinate
  end function sound

  !> Read the whole file as bytes (stream access never trips over line-ending quirks).
  subroutine load_file(path, cur, err)
    character(len=*), intent(in) :: path
    type(cursor_t), intent(out) :: cur
    type(error_t), allocatable, intent(out) :: err
    integer :: u, ios, nbytes
    integer(int64) :: size
    character(len=512) :: msg

    cur%path = path
    select case (file_kind(path, size))   ! a FIFO would block the read forever
    case (kind_folder, kind_special)
      call fatal_error(err, path // ": not a regular file (a folder, FIFO or device)")
      return
    case (kind_regular)
      if (size > huge(nbytes)) then
        call fatal_error(err, path // ": larger than 2 GiB; meshes are read up to 2 GiB")
        return
      end if
    end select
    open (newunit=u, file=path, status='old', action='read', access='stream', form='unformatted', &
          iostat=ios, iomsg=msg)
    if (ios /= 0) then
      call fatal_error(err, path // ": cannot open file: " // trim(msg))
      return
    end if
    inquire (unit=u, size=nbytes, iostat=ios, iomsg=msg)
    if (ios /= 0 .or. nbytes < 0) then
      call fatal_error(err, path // ": cannot determine the file size: " // trim(msg))
      close (u, iostat=ios)
      return
    end if
    allocate (character(len=nbytes) :: cur%buf)
    if (nbytes > 0) read (u, iostat=ios, iomsg=msg) cur%buf
    if (ios /= 0) then
      call fatal_error(err, path // ": read failed: " // trim(msg))
      close (u, iostat=ios)
      return
    end if
    close (u, iostat=ios)
    cur%pos = 1
    cur%line = 0
  end subroutine load_file

  !> Advance to the next line; s:e are its bounds in cur%buf without the line end, CR and
  !> surrounding blanks (e < s for a blank line). False at end of file.
  logical function next_line(cur, s, e)
    type(cursor_t), intent(inout) :: cur
    integer, intent(out) :: s, e
    integer :: nl
    s = cur%pos
    e = s - 1
    next_line = cur%pos <= len(cur%buf)
    if (.not. next_line) return
    nl = index(cur%buf(cur%pos:), achar(10))
    if (nl == 0) then
      e = len(cur%buf)
      cur%pos = len(cur%buf) + 1
    else
      e = cur%pos + nl - 2
      cur%pos = cur%pos + nl
    end if
    cur%line = cur%line + 1
    do while (e >= s)
      if (.not. is_blank(cur%buf(e:e))) exit
      e = e - 1
    end do
    do while (s <= e)
      if (.not. is_blank(cur%buf(s:s))) exit
      s = s + 1
    end do
  end function next_line

  !> next_line inside a section: end of file there means the file was truncated.
  logical function need_line(cur, s, e, section, err)
    type(cursor_t), intent(inout) :: cur
    integer, intent(out) :: s, e
    character(len=*), intent(in) :: section
    type(error_t), allocatable, intent(inout) :: err
    need_line = next_line(cur, s, e)
    if (.not. need_line) then
      cur%line = cur%line + 1
      call fail(err, cur, "unexpected end of file inside " // section // " (file truncated?)")
    else if (scan(cur%buf(s:e), '/,') > 0) then
      ! List-directed reads would take '/' as "stop here" and ',,' as "keep the old value",
      ! silently leaving numbers unset; Gmsh never writes either inside these sections.
      need_line = .false.
      call fail(err, cur, "unexpected ',' or '/' in " // section // " line '" // clip(cur%buf(s:e)) // "'")
    end if
  end function need_line

  subroutine expect_end(cur, section, err)
    type(cursor_t), intent(inout) :: cur
    character(len=*), intent(in) :: section
    type(error_t), allocatable, intent(inout) :: err
    integer :: s, e
    if (.not. need_line(cur, s, e, "$" // section, err)) return
    if (cur%buf(s:e) /= '$End' // section) then
      call fail(err, cur, "expected $End" // section // " (more entries than the header announced?), found '" &
                // clip(cur%buf(s:e)) // "'")
    end if
  end subroutine expect_end

  subroutine alloc_nodes(cur, raw, n, err)
    type(cursor_t), intent(in) :: cur
    type(raw_t), intent(inout) :: raw
    integer, intent(in) :: n
    type(error_t), allocatable, intent(inout) :: err
    integer :: stat
    allocate (raw%node_tag(n), raw%node_line(n), raw%x(3, n), stat=stat)
    if (stat /= 0) call fail(err, cur, "cannot allocate memory for the announced number of nodes")
  end subroutine alloc_nodes

  subroutine alloc_elems(cur, raw, n, err)
    type(cursor_t), intent(in) :: cur
    type(raw_t), intent(inout) :: raw
    integer, intent(in) :: n
    type(error_t), allocatable, intent(inout) :: err
    integer :: stat
    allocate (raw%elem_nodes(nen, n), raw%elem_line(n), stat=stat)
    if (stat /= 0) call fail(err, cur, "cannot allocate memory for the announced number of elements")
  end subroutine alloc_elems

  !> "path:line: msg" at the cursor's current line.
  subroutine fail(err, cur, msg)
    type(error_t), allocatable, intent(inout) :: err
    type(cursor_t), intent(in) :: cur
    character(len=*), intent(in) :: msg
    character(len=16) :: ln
    character(len=:), allocatable :: why
    write (ln, '(i0)') cur%line
    why = msg
    ! (the line that failed is the file's last and has no end: a copy or a write cut short,
    ! whose last number was read as another)
    if (cur%line > 0 .and. cur%pos > len(cur%buf) .and. len(cur%buf) > 0 .and. &
        index(msg, 'end of file') == 0) then
      if (cur%buf(len(cur%buf):len(cur%buf)) /= achar(10)) &
        why = msg // ' (the file ends in the middle of this line: is it cut off?)'
    end if
    call fatal_error(err, cur%path // ":" // trim(ln) // ": " // why)
  end subroutine fail

  !> At most 60 characters of a line for an error message.
  pure function clip(text) result(r)
    character(len=*), intent(in) :: text
    character(len=:), allocatable :: r
    if (len(text) > 60) then
      r = text(1:60) // '...'
    else
      r = text
    end if
  end function clip

  pure logical function is_blank(c)
    character, intent(in) :: c
    is_blank = c == ' ' .or. c == achar(9) .or. c == achar(13)
  end function is_blank

  !> Position of key in the ascending list a, or 0.
  pure integer function find_sorted(a, key)
    integer(i8), intent(in) :: a(:), key
    integer :: lo, hi, mid
    find_sorted = 0
    lo = 1
    hi = size(a)
    do while (lo <= hi)
      mid = lo + (hi - lo)/2
      if (a(mid) == key) then
        find_sorted = mid
        return
      else if (a(mid) < key) then
        lo = mid + 1
      else
        hi = mid - 1
      end if
    end do
  end function find_sorted
end module casca_gmsh_io
