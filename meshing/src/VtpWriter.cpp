#include "VtpWriter.h"

#include <cstdio>
#include <fstream>

#include "pneuma/sim/Error.h"

namespace pneuma::meshing {

void writeVtp(const TriangleMesh& mesh, const std::string& path) {
  std::ofstream out(path, std::ios::binary);
  if (!out) throw sim::Error(path + ": cannot open for writing");
  out << "<?xml version=\"1.0\"?>\n"
      << "<VTKFile type=\"PolyData\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
      << "  <PolyData>\n"
      << "    <Piece NumberOfPoints=\"" << mesh.vertexCount() << "\" NumberOfVerts=\"0\" NumberOfLines=\"0\""
      << " NumberOfStrips=\"0\" NumberOfPolys=\"" << mesh.triangleCount() << "\">\n"
      << "      <Points>\n"
      << "        <DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n";
  char buf[96];
  for (int v = 0; v < mesh.vertexCount(); ++v) {
    std::snprintf(buf, sizeof buf, "%.9g %.9g %.9g\n", mesh.vertices(0, v), mesh.vertices(1, v),
                  mesh.vertices(2, v));
    out << buf;
  }
  out << "        </DataArray>\n      </Points>\n      <Polys>\n"
      << "        <DataArray type=\"Int32\" Name=\"connectivity\" format=\"ascii\">\n";
  for (int f = 0; f < mesh.triangleCount(); ++f) {
    out << mesh.triangles(0, f) << ' ' << mesh.triangles(1, f) << ' ' << mesh.triangles(2, f) << '\n';
  }
  out << "        </DataArray>\n"
      << "        <DataArray type=\"Int32\" Name=\"offsets\" format=\"ascii\">\n";
  for (int f = 0; f < mesh.triangleCount(); ++f) out << 3 * (f + 1) << '\n';
  out << "        </DataArray>\n      </Polys>\n    </Piece>\n  </PolyData>\n</VTKFile>\n";
  if (!out) throw sim::Error(path + ": write failed");
}

}  // namespace pneuma::meshing
