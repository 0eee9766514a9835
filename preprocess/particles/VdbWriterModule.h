// VdbWriterModule: the interface of the module that writes OpenVDB points. Writing them is
// OpenVDB's own code (points::createPointDataGrid, io::Stream), the only part of flipscope that
// needs the OpenVDB library, which takes 40 to 60 ms of symbol relocations to load. So it lives
// in a module of its own (preprocess/vdbwriter/, libflipscope_vdb_writer.so), which VdbPoints.cpp
// loads when a .vdb is written: no other command loads OpenVDB, and a `flipscope` binary carried
// to a farm or GPU machine needs neither it nor the module unless it writes VDB files.
//
// The interface is one C function, looked up by name: what crosses it is plain data and the
// std::ostream the host writes through (module and host are built by the same compiler).
#pragma once

#include <cstddef>
#include <cstdint>
#include <ostream>

namespace flipscope::vdbwriter {

/// The module's file, found beside the `flipscope` binary (or in the build tree).
inline constexpr char kModuleFile[] = "libflipscope_vdb_writer.so";
/// The name of its WriteFunction.
inline constexpr char kEntryPoint[] = "flipscopeWriteVdbPoints";

/// The particles of one file: `count` positions (x y z floats, finite), and with `velocity` as
/// many velocities.
struct Points {
  const float* positions = nullptr;
  const float* velocities = nullptr;
  std::size_t count = 0;
  bool velocity = false;  ///< whether to write the attribute `v`
  double voxelSize = 0;  ///< of the point grid; 0: from the points, about 8 a voxel
};

/// Writes one PointDataGrid `particles` holding P (null codec) and, with velocities, `v`, as
/// io::Stream writes it, to `out`. Returns true, or false with a message in `error` (a position
/// too far from the origin for the voxel size, or OpenVDB's own errors). Exceptions of `out`
/// pass through.
using WriteFunction = bool (*)(const Points& points, std::ostream& out, char* error, std::size_t errorBytes);

}  // namespace flipscope::vdbwriter
