// The CPU grab-box SDF builder behind the SdfBackend interface (makeCpuSdfBackend in
// sdf_backend.h): what headless and OpenGL sessions build with, and where the GPU falls back.
#include <memory>

#include "sdf/sdf_backend.h"
#include "sdf/sdf_cpu.h"

namespace sdfg {
namespace {

class CpuBackend final : public SdfBackend {
 public:
  CpuBackend(unsigned threads, const CpuSdfOptions& options)
      : builder_(threads), options_(options) {}
  std::string_view name() const override { return "cpu"; }
  using SdfBackend::build;
  Status build(const MeshDistance& target, const Pose& objectFromHand, const GridBox& box,
               SdfGrid& out, const WorkLimit& limit) override {
    return builder_.build(target, objectFromHand, box, out, options_, limit);
  }

 private:
  CpuSdfBuilder builder_;
  CpuSdfOptions options_;
};

}  // namespace

std::unique_ptr<SdfBackend> makeCpuSdfBackend(unsigned threads, const CpuSdfOptions& options) {
  return std::make_unique<CpuBackend>(threads, options);
}

}  // namespace sdfg
