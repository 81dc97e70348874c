!> VTK XML output of cubic-triangle meshes for ParaView (and meshio).
!>
!> One .vtu per frame: an UnstructuredGrid of VTK_LAGRANGE_TRIANGLE cells (type 69), whose
!> 10-point order is casca's own (3 vertices, edge 1-2, edge 2-3, edge 3-1, centroid), so the
!> connectivity is written unpermuted. Array data goes in one AppendedData block, encoding "raw":
!> each array is a UInt64 byte count followed by the values in native byte order (declared in
!> byte_order), which is the smallest and fastest form ParaView reads, and meshio reads too.
!> The arrays' blocks are appended in the reverse order of their DataArray lines (offsets
!> fall down the header): meshio turns raw data into base64 by finding each block's DataArray
!> by its offset attribute, block after block, after rewriting the earlier blocks' offsets to
!> base64 positions, and takes the first match; in header order a rewritten offset that equals
!> a later block's raw offset made it read the wrong array (a 10 x 1 strip's frame:
!> von_mises_top rewritten to 25888, the raw offset of the cells' offsets). Reversed, the
!> block it looks for always comes before the rewritten ones. ParaView follows the offsets.
!> Linear triangles (VTK_TRIANGLE, type 5) are written the same way, for drawn surfaces that
!> are not shells (the rigid obstacles): the cell type follows conn's number of rows.
!> A .pvd collection lists the frames with their times, and a second part per frame (part 1:
!> the obstacles) where one is given.
!>
!> Every file is written to <path>.part and renamed onto <path> only when complete and closed,
!> so a reader (or a crash) never sees a half-written file under the final name. rename(2) on
!> one file system replaces the target atomically.
module casca_vtu_writer
  use, intrinsic :: iso_c_binding, only: c_char, c_int, c_null_char
  use, intrinsic :: iso_fortran_env, only: int8, int32, int64, real32
  use casca_kinds, only: dp
  use casca_error, only: error_t, fatal_error
  use casca_files, only: rename_file, close_complete, delete_file
  use casca_strings, only: itoa
  implicit none
  private
  public :: field_t, field, write_vtu, write_pvd

  !> A named array of point or cell data: v(ncomp, n), n = number of points or cells.
  type :: field_t
    character(len=:), allocatable :: name
    real(dp), allocatable :: v(:, :)
    logical :: single = .false.   !< written as Float32: half the bytes, 7 significant digits
  end type field_t

  integer, parameter :: vtk_lagrange_triangle = 69, vtk_triangle = 5
  integer, parameter :: nen = 10          !< points per cubic triangle
  integer, parameter :: msg_len = 512
  character(len=*), parameter :: nl = achar(10)



contains

  !> Build a field_t (so callers can write field('thickness', reshape(t, [1, n]))); single:
  !> write it as Float32 (for large derived fields viewed, not read back exactly).
  pure function field(name, v, single) result(f)
    character(len=*), intent(in) :: name
    real(dp), intent(in) :: v(:, :)
    logical, intent(in), optional :: single
    type(field_t) :: f
    f%name = name
    allocate (f%v, source=v)   ! (plain f%v = v trips a spurious gfortran 12 warning)
    if (present(single)) f%single = single
  end function field

  !> Write one UnstructuredGrid of cubic (or linear) triangles to path (.vtu).
  !> x(3, nnode) coordinates; conn(10, nelem) 1-based node numbers in casca order (or
  !> conn(3, nelem): linear triangles); point_fields(:)%v(ncomp, nnode),
  !> cell_fields(:)%v(ncomp, nelem); either may be size 0. labels: field data, one array named
  !> labels(k) holding k for each k, which names the values of a cell field (the obstacles':
  !> numbers that meshio and ParaView both read, where a string array meshio refuses)
  subroutine write_vtu(path, x, conn, point_fields, cell_fields, err, labels)
    character(len=*), intent(in) :: path
    real(dp), intent(in) :: x(:, :)
    integer, intent(in) :: conn(:, :)
    type(field_t), intent(in) :: point_fields(:), cell_fields(:)
    type(error_t), allocatable, intent(out) :: err
    character(len=*), intent(in), optional :: labels(:)

    character(len=:), allocatable :: xml, tmp
    character(len=msg_len) :: msg
    integer(int64), allocatable :: cell_offsets(:), bytes(:), offset(:)
    integer(int8), allocatable :: types(:)
    integer :: nnode, nelem, npc, i, k, nf, u, ios

    nnode = size(x, 2)
    nelem = size(conn, 2)
    npc = size(conn, 1)
    if (size(x, 1) /= 3) then
      call fatal_error(err, 'write_vtu: '//trim(path)//': x must have 3 rows, got ' &
                       //itoa(size(x, 1)))
      return
    end if
    if (npc /= nen .and. npc /= 3) then
      call fatal_error(err, 'write_vtu: '//trim(path)//': conn must have 10 or 3 rows, got ' &
                       //itoa(npc))
      return
    end if
    ! A bad node number would make ParaView read out of bounds or silently draw garbage.
    if (nelem > 0) then
      if (minval(conn) < 1 .or. maxval(conn) > nnode) then
        call fatal_error(err, 'write_vtu: '//trim(path)//': node number out of range 1..' &
                         //itoa(nnode)//' in conn')
        return
      end if
    end if
    call check_fields(path, 'point', point_fields, nnode, err)
    if (allocated(err)) return
    call check_fields(path, 'cell', cell_fields, nelem, err)
    if (allocated(err)) return

    ! XML header. Offsets count bytes from just after the '_' that opens the appended data;
    ! each block is an 8-byte (UInt64) length followed by the values. bytes: the blocks' values
    ! in header order (fields, points, connectivity, offsets, types), written last to first.
    nf = size(point_fields) + size(cell_fields)
    bytes = [(field_bytes(point_fields(i)), i=1, size(point_fields)), &
             (field_bytes(cell_fields(i)), i=1, size(cell_fields)), &
             8_int64*3*nnode, 8_int64*npc*nelem, 8_int64*nelem, 1_int64*nelem]
    allocate (offset(size(bytes)))
    offset(size(bytes)) = 0
    do k = size(bytes) - 1, 1, -1
      offset(k) = offset(k + 1) + 8_int64 + bytes(k + 1)
    end do
    xml = '<?xml version="1.0"?>'//nl &
          //'<VTKFile type="UnstructuredGrid" version="1.0" byte_order="'//byte_order() &
          //'" header_type="UInt64">'//nl &
          //'  <UnstructuredGrid>'//nl
    if (present(labels)) xml = xml//label_data(labels)
    xml = xml//'    <Piece NumberOfPoints="'//itoa(nnode)//'" NumberOfCells="'//itoa(nelem)//'">'//nl
    if (size(point_fields) > 0) then
      xml = xml//'      <PointData>'//nl
      do i = 1, size(point_fields)
        xml = xml//field_array(point_fields(i), offset(i))
      end do
      xml = xml//'      </PointData>'//nl
    end if
    if (size(cell_fields) > 0) then
      xml = xml//'      <CellData>'//nl
      do i = 1, size(cell_fields)
        xml = xml//field_array(cell_fields(i), offset(size(point_fields) + i))
      end do
      xml = xml//'      </CellData>'//nl
    end if
    xml = xml//'      <Points>'//nl &
          //data_array('Float64', 'Points', 3, offset(nf + 1)) &
          //'      </Points>'//nl &
          //'      <Cells>'//nl &
          //data_array('Int64', 'connectivity', 1, offset(nf + 2)) &
          //data_array('Int64', 'offsets', 1, offset(nf + 3)) &
          //data_array('UInt8', 'types', 1, offset(nf + 4)) &
          //'      </Cells>'//nl &
          //'    </Piece>'//nl &
          //'  </UnstructuredGrid>'//nl &
          //'  <AppendedData encoding="raw">'//nl//'   _'

    ! VTK's offsets array holds the end of each cell's run in connectivity (no leading 0).
    cell_offsets = [(int(npc, int64)*i, i=1, nelem)]
    types = [(int(merge(vtk_lagrange_triangle, vtk_triangle, npc == nen), int8), i=1, nelem)]

    tmp = trim(path)//'.part'
    open (newunit=u, file=tmp, access='stream', form='unformatted', status='replace', &
          action='write', iostat=ios, iomsg=msg)
    if (ios /= 0) then
      call fatal_error(err, 'write_vtu: cannot open '//tmp//' for writing: '//trim(msg))
      return
    end if

    ! The blocks in the reverse order of the header, at the offsets assigned above (module
    ! header: meshio). The meshio reader needs the data block to be followed directly by a
    ! newline.
    write (u, iostat=ios, iomsg=msg) xml
    if (ios == 0) write (u, iostat=ios, iomsg=msg) nbytes(1, int(nelem, int64)), types
    if (ios == 0) write (u, iostat=ios, iomsg=msg) nbytes(8, int(nelem, int64)), cell_offsets
    if (ios == 0) write (u, iostat=ios, iomsg=msg) &
      nbytes(8, size(conn, kind=int64)), int(conn, int64) - 1_int64   ! VTK numbers from 0
    if (ios == 0) write (u, iostat=ios, iomsg=msg) nbytes(8, size(x, kind=int64)), x
    do i = size(cell_fields), 1, -1
      if (ios == 0) call write_field(u, cell_fields(i), ios, msg)
    end do
    do i = size(point_fields), 1, -1
      if (ios == 0) call write_field(u, point_fields(i), ios, msg)
    end do
    if (ios == 0) write (u, iostat=ios, iomsg=msg) nl//'  </AppendedData>'//nl//'</VTKFile>'//nl

    call finish(u, ios, msg, tmp, trim(path), 'write_vtu', err)
  end subroutine write_vtu

  !> Write a ParaView collection (.pvd) listing files(i) (names relative to the .pvd's folder)
  !> at times(i). Rewritten whole on every call so that it is valid after every frame.
  !> parts(i), where not blank: a second dataset at times(i), as part 1 (ParaView shows both
  !> parts of the time together, as two blocks).
  subroutine write_pvd(path, files, times, err, parts)
    character(len=*), intent(in) :: path
    character(len=*), intent(in) :: files(:)
    real(dp), intent(in) :: times(:)
    type(error_t), allocatable, intent(out) :: err
    character(len=*), intent(in), optional :: parts(:)

    character(len=:), allocatable :: xml, tmp
    character(len=msg_len) :: msg
    character(len=32) :: tbuf
    integer :: i, u, ios

    if (size(files) /= size(times)) then
      call fatal_error(err, 'write_pvd: '//trim(path)//': '//itoa(size(files))//' files but ' &
                       //itoa(size(times))//' times')
      return
    end if
    if (present(parts)) then
      if (size(parts) /= size(files)) then
        call fatal_error(err, 'write_pvd: '//trim(path)//': '//itoa(size(files))//' files but ' &
                         //itoa(size(parts))//' parts')
        return
      end if
    end if

    xml = '<?xml version="1.0"?>'//nl &
          //'<VTKFile type="Collection" version="0.1" byte_order="'//byte_order()//'">'//nl &
          //'  <Collection>'//nl
    do i = 1, size(files)
      ! 17 significant digits so the time read back is the same double.
      write (tbuf, '(es25.16e3)') times(i)
      xml = xml//'    <DataSet timestep="'//trim(adjustl(tbuf))//'" group="" part="0" file="' &
            //xml_escape(trim(files(i)))//'"/>'//nl
      if (.not. present(parts)) cycle
      if (len_trim(parts(i)) > 0) xml = xml//'    <DataSet timestep="'//trim(adjustl(tbuf)) &
                                        //'" group="" part="1" file="'//xml_escape(trim(parts(i)))//'"/>'//nl
    end do
    xml = xml//'  </Collection>'//nl//'</VTKFile>'//nl

    tmp = trim(path)//'.part'
    open (newunit=u, file=tmp, access='stream', form='unformatted', status='replace', &
          action='write', iostat=ios, iomsg=msg)
    if (ios /= 0) then
      call fatal_error(err, 'write_pvd: cannot open '//tmp//' for writing: '//trim(msg))
      return
    end if
    write (u, iostat=ios, iomsg=msg) xml
    call finish(u, ios, msg, tmp, trim(path), 'write_pvd', err)
  end subroutine write_pvd

  !> Close the temporary file and move it onto its final name; on any failure delete it.
  subroutine finish(u, ios_write, msg_write, tmp, path, who, err)
    integer, intent(in) :: u, ios_write
    character(len=*), intent(in) :: msg_write, tmp, path, who
    type(error_t), allocatable, intent(out) :: err
    integer :: ios, tmp_unit

    if (ios_write /= 0) then
      close (u, status='delete', iostat=ios)
      call fatal_error(err, who//': error writing '//tmp//': '//trim(msg_write))
      return
    end if
    if (.not. close_complete(u, tmp)) then
      call delete_file(tmp)
      call fatal_error(err, who//': error writing '//tmp//' (is the disk full?)')
      return
    end if
    if (.not. rename_file(tmp, path)) then
      ! Do not leave the complete-looking temporary behind.
      open (newunit=tmp_unit, file=tmp, status='old', iostat=ios)
      if (ios == 0) close (tmp_unit, status='delete', iostat=ios)
      call fatal_error(err, who//': cannot rename '//tmp//' to '//path)
      return
    end if
  end subroutine finish

  !> Check names and shapes of point or cell fields against n points or cells.
  subroutine check_fields(path, kind_name, fields, n, err)
    character(len=*), intent(in) :: path, kind_name
    type(field_t), intent(in) :: fields(:)
    integer, intent(in) :: n
    type(error_t), allocatable, intent(out) :: err
    integer :: i

    do i = 1, size(fields)
      if (.not. allocated(fields(i)%name) .or. .not. allocated(fields(i)%v)) then
        call fatal_error(err, 'write_vtu: '//trim(path)//': '//kind_name//' field '//itoa(i) &
                         //' has no name or no values')
        return
      end if
      if (len_trim(fields(i)%name) == 0) then
        call fatal_error(err, 'write_vtu: '//trim(path)//': '//kind_name//' field '//itoa(i) &
                         //' has an empty name')
        return
      end if
      if (size(fields(i)%v, 1) < 1 .or. size(fields(i)%v, 2) /= n) then
        call fatal_error(err, 'write_vtu: '//trim(path)//': '//kind_name//' field "' &
                         //fields(i)%name//'" has shape ('//itoa(size(fields(i)%v, 1))//',' &
                         //itoa(size(fields(i)%v, 2))//'), expected (ncomp>=1,'//itoa(n)//')')
        return
      end if
    end do
  end subroutine check_fields

  !> The <DataArray .../> line of a field at offset (Float32 or Float64).
  function field_array(f, offset) result(s)
    type(field_t), intent(in) :: f
    integer(int64), intent(in) :: offset
    character(len=:), allocatable :: s
    if (f%single) then
      s = data_array('Float32', f%name, size(f%v, 1), offset)
    else
      s = data_array('Float64', f%name, size(f%v, 1), offset)
    end if
  end function field_array

  !> The bytes of a field's values in its block, as write_field writes them
  pure integer(int64) function field_bytes(f)
    type(field_t), intent(in) :: f
    field_bytes = merge(4_int64, 8_int64, f%single)*size(f%v, kind=int64)
  end function field_bytes

  !> A field's appended block: its byte count, then its values as declared by field_array.
  subroutine write_field(u, f, ios, msg)
    integer, intent(in) :: u
    type(field_t), intent(in) :: f
    integer, intent(out) :: ios
    character(len=*), intent(inout) :: msg
    if (f%single) then
      write (u, iostat=ios, iomsg=msg) nbytes(4, size(f%v, kind=int64)), real(f%v, real32)
    else
      write (u, iostat=ios, iomsg=msg) nbytes(8, size(f%v, kind=int64)), f%v
    end if
  end subroutine write_field

  !> The FieldData of labels: per label an Int32 array named so, holding its number
  function label_data(labels) result(s)
    character(len=*), intent(in) :: labels(:)
    character(len=:), allocatable :: s
    integer :: k
    s = '    <FieldData>'//nl
    do k = 1, size(labels)
      s = s//'      <DataArray type="Int32" Name="'//xml_escape(trim(labels(k))) &
          //'" NumberOfTuples="1" format="ascii">'//itoa(k)//'</DataArray>'//nl
    end do
    s = s//'    </FieldData>'//nl
  end function label_data

  !> One <DataArray .../> line for appended data at offset.
  function data_array(vtk_type, name, ncomp, offset) result(s)
    character(len=*), intent(in) :: vtk_type, name
    integer, intent(in) :: ncomp
    integer(int64), intent(in) :: offset
    character(len=:), allocatable :: s
    s = '        <DataArray type="'//vtk_type//'" Name="'//xml_escape(name) &
        //'" NumberOfComponents="'//itoa(ncomp)//'" format="appended" offset="' &
        //itoa(offset)//'"/>'//nl
  end function data_array

  !> The UInt64 length header of an appended block of n values of bytes_per_value each.
  pure function nbytes(bytes_per_value, n) result(b)
    integer, intent(in) :: bytes_per_value
    integer(int64), intent(in) :: n
    integer(int64) :: b
    b = int(bytes_per_value, int64)*n
  end function nbytes

  !> Byte order of this machine, for the byte_order attribute (raw data is written natively).
  pure function byte_order() result(s)
    character(len=:), allocatable :: s
    integer(int8) :: bytes(4)
    bytes = transfer(1_int32, bytes)
    if (bytes(1) == 1_int8) then
      s = 'LittleEndian'
    else
      s = 'BigEndian'
    end if
  end function byte_order

  !> Escape the characters that would break an XML attribute value.
  pure function xml_escape(s) result(r)
    character(len=*), intent(in) :: s
    character(len=:), allocatable :: r
    integer :: i
    r = ''
    do i = 1, len(s)
      select case (s(i:i))
      case ('&')
        r = r//'&amp;'
      case ('<')
        r = r//'&lt;'
      case ('>')
        r = r//'&gt;'
      case ('"')
        r = r//'&quot;'
      case default
        r = r//s(i:i)
      end select
    end do
  end function xml_escape

end module casca_vtu_writer
