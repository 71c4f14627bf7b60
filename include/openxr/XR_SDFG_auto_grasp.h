// XR_SDFG_auto_grasp: the extension of the SDF Autograsp API layer (XR_APILAYER_SDFG_autograsp).
//
// An app registers graspable objects (a triangle mesh and where it is) on a session; when the
// user squeezes a controller (or closes a tracked hand) with an object in the hand's grab box,
// the layer closes the hand's fingers onto the object's real surface, and the ordinary
// xrLocateHandJointsEXT returns the grasping hand. xrGetGraspStateSDFG says which object a hand
// holds, how far each finger closed and where it touches.
//
// Enable it like any extension: list XR_SDFG_AUTO_GRASP_EXTENSION_NAME in
// XrInstanceCreateInfo::enabledExtensionNames, then fetch the functions with
// xrGetInstanceProcAddr. Include <openxr/openxr.h> first; for the Vulkan buffer variant define
// XR_USE_GRAPHICS_API_VULKAN and include <vulkan/vulkan.h> and <openxr/openxr_platform.h> first.
//
// Numbers: the extension is not in the Khronos registry. It uses extension number 9901, so its
// enum values lie in 1009900000..1009900999 (1000000000 + (9901 - 1) * 1000 + n), a range no
// registered extension uses (registered numbers are below 1000 as of OpenXR 1.1.62).
//
// Errors every function returns besides XR_SUCCESS: XR_ERROR_HANDLE_INVALID (a null, destroyed
// or foreign handle), XR_ERROR_VALIDATION_FAILURE (a null pointer, a wrong `type`, a bad enum or
// an out-of-range number), XR_ERROR_RUNTIME_FAILURE (a failure inside the layer). A function that
// fails changes nothing.
#ifndef XR_SDFG_AUTO_GRASP_H_
#define XR_SDFG_AUTO_GRASP_H_ 1

#ifdef __cplusplus
extern "C" {
#endif

#define XR_SDFG_auto_grasp 1
#define XR_SDFG_auto_grasp_SPEC_VERSION 1
#define XR_SDFG_AUTO_GRASP_EXTENSION_NAME "XR_SDFG_auto_grasp"

XR_DEFINE_HANDLE(XrGraspTargetSDFG)

// Structure and object types (extension number 9901).
#define XR_TYPE_GRASP_TARGET_CREATE_INFO_SDFG ((XrStructureType)1009900000)
#define XR_TYPE_GRASP_TARGET_VERTICES_SDFG ((XrStructureType)1009900001)
#define XR_TYPE_GRASP_TARGET_VULKAN_BUFFERS_SDFG ((XrStructureType)1009900002)
#define XR_TYPE_GRASP_STATE_GET_INFO_SDFG ((XrStructureType)1009900003)
#define XR_TYPE_GRASP_STATE_SDFG ((XrStructureType)1009900004)
#define XR_TYPE_GRASP_OPTIONS_SDFG ((XrStructureType)1009900005)
#define XR_TYPE_GRASP_TARGET_PLACEMENT_SDFG ((XrStructureType)1009900006)
#define XR_OBJECT_TYPE_GRASP_TARGET_SDFG ((XrObjectType)1009900000)

// Limits, so a stray count cannot exhaust memory.
#define XR_MAX_GRASP_TARGET_VERTICES_SDFG (1u << 24)
#define XR_MAX_GRASP_TARGET_INDICES_SDFG (3u << 24)
#define XR_MAX_GRASP_SOLVER_NAME_SIZE_SDFG 64
#define XR_GRASP_FINGER_COUNT_SDFG 5

// Where a target is: `pose` in `space`, located at every frame, so a target in an action space
// or an anchor follows it. The mesh's vertices are in the target's own frame (metres).
typedef struct XrGraspTargetPlacementSDFG {
  XrStructureType type;  // XR_TYPE_GRASP_TARGET_PLACEMENT_SDFG
  const void* XR_MAY_ALIAS next;
  XrSpace space;  // a space of the target's session
  XrPosef pose;   // the target frame in `space`; the orientation must be a unit quaternion
} XrGraspTargetPlacementSDFG;

// Mesh as CPU arrays. The layer copies them; the app keeps ownership.
// vertexCount: number of vertices (xyz float triples in `vertices`), 3..XR_MAX_..._VERTICES;
// indexCount: number of uint32 indices, a multiple of 3, 3..XR_MAX_..._INDICES, each below
// vertexCount. Every coordinate must be finite; no triangle may repeat a vertex.
typedef struct XrGraspTargetVerticesSDFG {
  XrStructureType type;  // XR_TYPE_GRASP_TARGET_VERTICES_SDFG
  const void* XR_MAY_ALIAS next;
  uint32_t vertexCount;
  const XrVector3f* vertices;
  uint32_t indexCount;      // on create: required; on update: must be 0 (topology is fixed)
  const uint32_t* indices;  // on update: must be NULL
} XrGraspTargetVerticesSDFG;

#ifdef XR_USE_GRAPHICS_API_VULKAN
// Mesh as Vulkan buffers of the session's VkDevice (a skinned mesh the app already writes on
// the GPU). Vertex i's position is 3 floats at vertexOffset + i * vertexStride bytes; indices
// are uint32 at indexOffset. The buffers must be created with VK_BUFFER_USAGE_STORAGE_BUFFER_BIT
// and outlive the target; the app's writes must be complete (by a queue submission the layer's
// work follows) before the xrSyncActions that samples them. Sessions without a Vulkan binding
// return XR_ERROR_GRAPHICS_DEVICE_INVALID.
typedef struct XrGraspTargetVulkanBuffersSDFG {
  XrStructureType type;  // XR_TYPE_GRASP_TARGET_VULKAN_BUFFERS_SDFG
  const void* XR_MAY_ALIAS next;
  VkBuffer vertexBuffer;
  VkDeviceSize vertexOffset;
  uint32_t vertexStride;  // bytes, >= 12 and a multiple of 4
  uint32_t vertexCount;
  VkBuffer indexBuffer;
  VkDeviceSize indexOffset;
  uint32_t indexCount;
} XrGraspTargetVulkanBuffersSDFG;
#endif

// Chain exactly one mesh struct (XrGraspTargetVerticesSDFG or XrGraspTargetVulkanBuffersSDFG)
// on `next`.
typedef struct XrGraspTargetCreateInfoSDFG {
  XrStructureType type;  // XR_TYPE_GRASP_TARGET_CREATE_INFO_SDFG
  const void* XR_MAY_ALIAS next;
  XrGraspTargetPlacementSDFG placement;
} XrGraspTargetCreateInfoSDFG;

typedef struct XrGraspStateGetInfoSDFG {
  XrStructureType type;  // XR_TYPE_GRASP_STATE_GET_INFO_SDFG
  const void* XR_MAY_ALIAS next;
  XrHandEXT hand;  // XR_HAND_LEFT_EXT or XR_HAND_RIGHT_EXT
} XrGraspStateGetInfoSDFG;

typedef struct XrGraspFingerStateSDFG {
  float curl;               // 0 open .. 1 closed: how far the finger is allowed to close
  XrBool32 inContact;       // it stopped on the surface (XR_FALSE: it closes without touching)
  XrVector3f contactPoint;  // target frame: centre of the touching fingertip sphere
  float distance;           // signed distance of the target at contactPoint (about the tip radius)
} XrGraspFingerStateSDFG;

// Output. Fingers in thumb, index, middle, ring, little order.
typedef struct XrGraspStateSDFG {
  XrStructureType type;  // XR_TYPE_GRASP_STATE_SDFG
  void* XR_MAY_ALIAS next;
  XrBool32 isGrasping;       // a target is held and its solved pose is being applied
  XrGraspTargetSDFG target;  // the held target, XR_NULL_HANDLE when none
  float squeeze;             // the grab input the layer read this frame, 0..1
  XrGraspFingerStateSDFG fingers[XR_GRASP_FINGER_COUNT_SDFG];
} XrGraspStateSDFG;

// Solver strategies; the layer's configuration picks the default.
typedef enum XrGraspSolverSDFG {
  XR_GRASP_SOLVER_DEFAULT_SDFG = 0,  // the configured strategy (see docs/layer.md)
  XR_GRASP_SOLVER_PAPER_SDFG = 1,    // the paper's per-finger tip sweep
  XR_GRASP_SOLVER_OURS_SDFG = 2,     // whole-finger, conservative advancement, refined stop
  XR_GRASP_SOLVER_MAX_ENUM_SDFG = 0x7FFFFFFF
} XrGraspSolverSDFG;

// Options of one session, applied from the next grab. A zero field keeps the layer's default.
typedef struct XrGraspOptionsSDFG {
  XrStructureType type;  // XR_TYPE_GRASP_OPTIONS_SDFG
  const void* XR_MAY_ALIAS next;
  XrGraspSolverSDFG solver;
  float tipRadius;      // metres, 0 = each finger's own tip radius; else in (0, 0.05]
  XrPosef boxPose;      // grab box centre and axes in the wrist joint's frame (ignored when
                        // boxSize is zero)
  XrVector3f boxSize;   // edge lengths x y z in metres, each in (0, 1]; all zero = default
  uint32_t resolution;  // nodes per axis, 0 or 2..128
  float curlStep;       // curl step along each finger's curve, 0 or (1e-5, 1]
  float grabThreshold;  // squeeze that starts a grab, 0 or (0, 1]; release is 0.8 of it
} XrGraspOptionsSDFG;

typedef XrResult(XRAPI_PTR* PFN_xrCreateGraspTargetSDFG)(
    XrSession session, const XrGraspTargetCreateInfoSDFG* createInfo, XrGraspTargetSDFG* target);
typedef XrResult(XRAPI_PTR* PFN_xrDestroyGraspTargetSDFG)(XrGraspTargetSDFG target);
// New vertex positions (same count, same topology): animated and skinned meshes. Pass an
// XrGraspTargetVerticesSDFG with indexCount 0 (CPU targets), or an
// XrGraspTargetVulkanBuffersSDFG (the layer re-reads the buffers; same counts).
typedef XrResult(XRAPI_PTR* PFN_xrUpdateGraspTargetVerticesSDFG)(XrGraspTargetSDFG target,
                                                                 const void* vertices);
typedef XrResult(XRAPI_PTR* PFN_xrSetGraspTargetPlacementSDFG)(
    XrGraspTargetSDFG target, const XrGraspTargetPlacementSDFG* placement);
typedef XrResult(XRAPI_PTR* PFN_xrGetGraspStateSDFG)(XrSession session,
                                                     const XrGraspStateGetInfoSDFG* getInfo,
                                                     XrGraspStateSDFG* state);
typedef XrResult(XRAPI_PTR* PFN_xrSetGraspOptionsSDFG)(XrSession session,
                                                       const XrGraspOptionsSDFG* options);

#ifdef __cplusplus
}
#endif

#endif  // XR_SDFG_AUTO_GRASP_H_
