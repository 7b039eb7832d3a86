// Test program for the browser tests: a physical object whose 3D model is a mesh file (an STL
// tetrahedron the program writes into its working directory) next to a box; runs until SIGTERM.
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <thread>

#include "RoboticPlatform.hpp"

namespace {

class MeshPart : public PhysicalObject {
 public:
  MeshPart(const std::string& name, std::string file) : PhysicalObject(name), file_(std::move(file)) {
    publishObject();  // complete: the Scene Viewer may use it
  }
  ~MeshPart() override { withdrawObject(); }  // first: the Scene Viewer keeps off from here on
  Model3D get3DModel() const override {
    Model3D m;
    Shape mesh;
    mesh.kind = ShapeKind::Mesh;
    mesh.meshFile = file_;
    mesh.size = Vector<3>{{0.5}, {0.5}, {0.5}};
    mesh.color = Color{0.2, 0.6, 0.9, 1.0};
    m.shapes.push_back(mesh);
    Shape box;
    box.pose = translation(0.5, 0, 0.05);
    box.size = Vector<3>{{0.1}, {0.1}, {0.1}};
    m.shapes.push_back(box);
    return m;
  }

 private:
  std::string file_;
};

}  // namespace

int main(int argc, char* argv[]) {
  RoboticPlatform::init(argc, argv);
  const std::string file = (std::filesystem::current_path() / "part.stl").string();
  {
    std::ofstream stl(file);
    const char* facets[4][3] = {{"0 0 0", "1 0 0", "0 1 0"}, {"0 0 0", "0 0 1", "1 0 0"},
                                {"0 0 0", "0 1 0", "0 0 1"}, {"1 0 0", "0 0 1", "0 1 0"}};
    stl << "solid part\n";
    for (const auto& f : facets) {
      stl << " facet normal 0 0 0\n  outer loop\n";
      for (const char* v : f) stl << "   vertex " << v << "\n";
      stl << "  endloop\n endfacet\n";
    }
    stl << "endsolid part\n";
  }
  MeshPart part("part", file);
  std::cout << "mesh_cell: part drawn from " << file << std::endl;
  while (!ObjectManager::isShutdownRequested()) std::this_thread::sleep_for(std::chrono::milliseconds(50));
  return 0;
}
