#pragma once
// GLSL sources of the renderer (shaders.cpp). Uniforms are set by name; samplers
// have fixed texture units (layout(binding = N)), named below.
namespace lumar::gl::shaders {

// Vertex stages.
extern const char* const kFullscreenVertex;  // one triangle covering the viewport
extern const char* const kMeshVertex;        // model -> world -> clip; world position and normal out

// Functions shared by fragment stages, inserted after their #version line (with_glsl_library).
extern const char* const kCameraResponseGlsl;  // decoded(code): the response's table, or sRGB

// Fragment stages.
extern const char* const kBackgroundFragment;     // undistorted video, decoded to linear (+ kCameraResponseGlsl)
extern const char* const kDepthOnlyFragment;      // proxy room as occluder
extern const char* const kShadedObjectFragment;   // albedo * E(n) / pi * exposure, E from SH9 or the irradiance volume
                                                  // (+ kIrradianceVolumeGlsl)
extern const char* const kWorldPositionFragment;  // (x, y, z, 1)
extern const char* const kRoomRadianceFragment;   // environment map projected from its capture point
// linear -> the camera's codes, rows flipped for read-back; the camera's noise (+ kCameraResponseGlsl)
extern const char* const kEncodeFragment;
extern const char* const kBlurFragment;          // one pass of the camera's blur on rendered pixels
extern const char* const kResampleFragment;      // rendered pixels resampled as the video was, after their clipping
extern const char* const kCoveredFragment;       // 1: where an object is (its coverage, multisampled)
extern const char* const kAntialiasFragment;     // outline pixels mixed by the objects' coverage
extern const char* const kWeightedCopyFragment;  // the linear image times a weight (motion blur's sum)

constexpr int kVideoUnit = 0, kUndistortionMapUnit = 1, kEnvironmentUnit = 2, kLinearImageUnit = 3;
// The camera response as look-up tables (Renderer::set_video_radiometry).
constexpr int kResponseDecodeUnit = 4, kResponseEncodeUnit = 5;
// The blur's input of this pass (the first pass's is the linear image itself).
constexpr int kBlurSourceUnit = 6;
// The objects' coverage per pixel (R8), for the antialiasing pass.
constexpr int kCoverageUnit = 7;
// A copy of the encoded output (RGBA8, OpenCV rows), for the resample pass.
constexpr int kEncodedUnit = 8;

}  // namespace lumar::gl::shaders
