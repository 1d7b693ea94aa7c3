/* Portability layer: the few qualifiers, types and maths calls that differ between C++, CUDA and
 * OpenCL C. Everything under kernel/include/cohort/kernel/ is written against these names only. OpenCL C 1.2 is the
 * lowest common denominator: no references, no overloading, no templates, explicit __global pointers. */
#ifndef COHORT_KERNEL_PORTABLE_H
#define COHORT_KERNEL_PORTABLE_H

#if defined(__OPENCL_VERSION__)
  /* Always inlined, as CUDA's __forceinline__: NVIDIA's OpenCL compiler left a large one-caller function (the
   * vertex's shading after its lights) as a call, and that build faulted at frame 58 of every 720p test-map
   * run (error -9999); inlined, it renders them (docs/integrator.md, "Inlining on OpenCL"). */
  #define KFN static inline __attribute__((always_inline))
  #define KFN_OUTLINED static
  #define KGLOBAL __global
  #define KCONSTANT __constant
  typedef uint kuint;
  typedef int kint;
  #define k_sqrt(x) sqrt(x)
  #define k_fabs(x) fabs(x)
  #define k_fmin(a, b) fmin(a, b)
  #define k_fmax(a, b) fmax(a, b)
  #define k_pow(a, b) pow(a, b)
  #define k_exp(x) exp(x)
  #define k_floor(x) floor(x)
  #define k_log2(x) log2(x)
  #define k_cos(x) cos(x)
  #define k_sin(x) sin(x)
  #define k_atan2(y, x) atan2(y, x)
  #define K_INF INFINITY
#else
  #if defined(__CUDACC__) && defined(K_CUDA_DEVICE_ONLY)
    /* A kernel translation unit: device-only lets tracer hooks use device intrinsics (tex1Dfetch). */
    #define KFN static __device__ __forceinline__
  #elif defined(__CUDACC__)
    #define KFN static __host__ __device__ __forceinline__
  #else
    #define KFN static inline
  #endif
  /* KFN_OUTLINED: a function called from several places of the integrator that should exist once, the
   * BVH traversal (camera, shadow and bounce rays). Inlined into each call site, the CUDA kernel carried
   * four copies of it; as one called function the test map frame went from 6.2 to 4.2 ms on one H100
   * (docs/integrator.md, "CUDA kernel shape"). Outlining the surface and lighting functions as well was
   * slower (4.6 ms). */
  #if defined(KFN_OUTLINED)
    /* the includer's choice (a kernel of one walk inlines it) */
  #elif defined(__CUDACC__) && defined(K_CUDA_DEVICE_ONLY)
    #define KFN_OUTLINED static __device__ __noinline__
  #elif defined(__CUDACC__)
    #define KFN_OUTLINED static __host__ __device__ __noinline__
  #else
    #define KFN_OUTLINED static inline
  #endif
  #define KGLOBAL
  #define KCONSTANT static const
  #include <stdint.h>
  #include <string.h>
  #include <math.h>
  typedef uint32_t kuint;
  typedef int32_t kint;
  #define k_sqrt(x) sqrtf(x)
  #define k_fabs(x) fabsf(x)
  #if defined(__CUDACC__)
    #define k_fmin(a, b) fminf(a, b)
    #define k_fmax(a, b) fmaxf(a, b)
  #else
    /* On the host, fminf/fmaxf are libm calls (GCC inlines them only under -ffinite-math-only), and
     * they sat high in the Embree tracer's profile. Same results, NaN operands included (the other
     * operand wins), in a few inlined instructions. */
    static inline float k_fmin_host(float a, float b) { return (a < b || b != b) ? a : b; }
    static inline float k_fmax_host(float a, float b) { return (a > b || b != b) ? a : b; }
    #define k_fmin(a, b) k_fmin_host(a, b)
    #define k_fmax(a, b) k_fmax_host(a, b)
  #endif
  #define k_pow(a, b) powf(a, b)
  #define k_exp(x) expf(x)
  #define k_floor(x) floorf(x)
  #define k_log2(x) log2f(x)
  #define k_cos(x) cosf(x)
  #define k_sin(x) sinf(x)
  #define k_atan2(y, x) atan2f(y, x)
  #define K_INF INFINITY
#endif

#define K_PI 3.14159265358979323846f

/* k_load4(p): four consecutive floats from a global array whose element size keeps them 16-byte
 * aligned (BVH nodes, vertex positions, triangles, instance matrices). On the GPU this is one 128-bit
 * load through the read-only cache where scalar loads of a struct's fields cost four instructions and,
 * in the BVH walk, most of its latency. k_as_uint reads an integer stored in a float lane;
 * k_bits_to_float builds a float from its bits (band_pack.h's shared exponent). */
#if defined(__OPENCL_VERSION__)
  typedef float4 KFloat4;
  #define k_load4(p) vload4(0, (p))
  #define k_as_uint(f) as_uint(f)
  #define k_bits_to_float(u) as_float(u)
#elif defined(__CUDACC__)
  typedef float4 KFloat4;
  KFN KFloat4 k_load4(const float* p) {
  #if defined(__CUDA_ARCH__)
    return __ldg((const float4*)p);
  #else
    return make_float4(p[0], p[1], p[2], p[3]);
  #endif
  }
  KFN kuint k_as_uint(float f) {
  #if defined(__CUDA_ARCH__)
    return __float_as_uint(f);
  #else
    kuint u;
    memcpy(&u, &f, sizeof u);
    return u;
  #endif
  }
  KFN float k_bits_to_float(kuint u) {
  #if defined(__CUDA_ARCH__)
    return __uint_as_float(u);
  #else
    float f;
    memcpy(&f, &u, sizeof f);
    return f;
  #endif
  }
#else
  typedef struct KFloat4 { float x, y, z, w; } KFloat4;
  static inline KFloat4 k_load4(const float* p) {
    KFloat4 v = {p[0], p[1], p[2], p[3]};
    return v;
  }
  static inline kuint k_as_uint(float f) {
    kuint u;
    memcpy(&u, &f, sizeof u);
    return u;
  }
  static inline float k_bits_to_float(kuint u) {
    float f;
    memcpy(&f, &u, sizeof f);
    return f;
  }
#endif

#endif
