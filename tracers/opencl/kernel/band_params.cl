/* The band kernels' parameters (the scene, the frame, the band and its row ray counts), shared by the
 * megakernels (render_band.cl) and the wavefront's kernels (wavefront.cl). */
#define COHORT_BAND_KERNEL_PARAMS                                                                               \
      __global const KVertex* vertices, __global const KVertexColor* vertex_colors,                      \
      __global const KTriangle* triangles, __global const KBvhNode* blas_nodes, __global const KBlas* blases,          \
      __global const KInstance* instances, __global const KBvhNode* tlas_nodes, __global const KMaterial* materials,   \
      __global const KTexture* textures, __global const kuint* texels, __global const KLight* lights,                \
      __global const KLightNode* light_nodes, __global const KEmissiveTriangle* emissive,                             \
      __global const KFrameParams* params_in, __global const KCamera* camera_in, __global float* band_rgba,           \
      __global uint* row_rays
#define COHORT_BAND_KERNEL_ARGS                                                                                 \
  vertices, vertex_colors, triangles, blas_nodes, blases, instances, tlas_nodes, materials, textures, texels,     \
      lights, light_nodes, emissive, params_in, camera_in, band_rgba, row_rays

