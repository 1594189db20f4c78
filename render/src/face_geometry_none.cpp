// CudaGeometry in a build without CUDA: it says so.
#include "emoface/common/error.h"
#include "emoface/render/face_geometry.h"

namespace emoface::render {

bool cuda_geometry_available() { return false; }

struct CudaGeometry::Impl {};

CudaGeometry::CudaGeometry(const FaceGeometry&) {
    fail<EnvironmentError>("render: CUDA geometry: this build has no CUDA (nvcc was not found)");
}
CudaGeometry::~CudaGeometry() = default;
void CudaGeometry::run(const expression::RigFrame&, const std::vector<float*>&, const std::vector<float*>&) {}
void* CudaGeometry::stream() const { return nullptr; }
void CudaGeometry::finish() {}
void CudaGeometry::wait_for(void*) {}
void CudaGeometry::join_into(void*) {}
int CudaGeometry::split_vertices() const { return 0; }

}  // namespace emoface::render
