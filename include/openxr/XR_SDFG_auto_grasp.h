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
// Errors and rules. Every function returns XR_SUCCESS or one of the codes below, and a function
// that fails changes nothing (no target is made or removed, no option or placement changes, no
// output is written). Rules that hold for every function:
// - XR_ERROR_HANDLE_INVALID: a session or target handle that is XR_NULL_HANDLE, destroyed,
//   of another kind (an XrSpace passed as an XrSession) or not made through this layer; an
//   XrSpace that is null, destroyed or not a reference or action space of the target's session.
// - XR_ERROR_VALIDATION_FAILURE: a null pointer argument; a `type` that is not the one named on
//   the struct; an enum field outside its listed values (checked as a 32-bit integer, so any bit
//   pattern is safe); a float that is NaN or infinite; a number outside its documented range; a
//   `next` chain longer than 32 structs (a cycle, such as a struct whose `next` points to
//   itself, counts as too long: it is refused, never followed forever).
// - XR_ERROR_POSE_INVALID: a pose whose orientation is not a unit quaternion (|q|^2 within 1e-3
//   of 1); a finite pose is checked first (non-finite: XR_ERROR_VALIDATION_FAILURE).
// - XR_ERROR_HANDLE_INVALID also: a call racing with the destruction of its session (or its
//   target) on another thread finds the handle gone. (Up to version 2 that was
//   XR_ERROR_SESSION_LOST, which the spec reserves for a session the runtime lost.)
// - XR_ERROR_OUT_OF_MEMORY: the layer could not allocate what the call needs.
// - XR_ERROR_RUNTIME_FAILURE: a failure inside the layer (logged).
// Function-specific errors are listed at each function type below.
#ifndef XR_SDFG_AUTO_GRASP_H_
#define XR_SDFG_AUTO_GRASP_H_ 1

#ifdef __cplusplus
extern "C" {
#endif

#define XR_SDFG_auto_grasp 1
#define XR_SDFG_auto_grasp_SPEC_VERSION 3
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
#define XR_TYPE_GRASP_BUILD_INFO_SDFG ((XrStructureType)1009900007)
#define XR_TYPE_GRASP_TARGETS_SETUP_INFO_SDFG ((XrStructureType)1009900008)
#define XR_OBJECT_TYPE_GRASP_TARGET_SDFG ((XrObjectType)1009900000)

// Limits, so a stray count cannot exhaust memory.
#define XR_MAX_GRASP_TARGET_VERTICES_SDFG (1u << 24)
#define XR_MAX_GRASP_TARGET_INDICES_SDFG (3u << 24)
// Unused: no function takes a solver name (strategies are XrGraspSolverSDFG values). Kept so that
// version 1 sources that name it still compile.
#define XR_MAX_GRASP_SOLVER_NAME_SIZE_SDFG 64
#define XR_GRASP_FINGER_COUNT_SDFG 5

// Where a target is: `pose` in `space`, located at every frame, so a target in an action space
// follows it. `space` must be a reference space or an action space the app created on the
// target's session (the layer checks that the handle is one of them, and never passes a space it
// cannot vouch for to the runtime); other kinds of spaces (spatial anchors of vendor extensions)
// are refused with XR_ERROR_HANDLE_INVALID: locate an anchor yourself and set the target's pose in
// a reference space with xrSetGraspTargetPlacementSDFG each frame it moves. Targets in one space
// cost one xrLocateSpace per frame together, whatever their number. The mesh's vertices are in
// the target's own frame (metres).
typedef struct XrGraspTargetPlacementSDFG {
  XrStructureType type;  // XR_TYPE_GRASP_TARGET_PLACEMENT_SDFG
  const void* XR_MAY_ALIAS next;
  XrSpace space;  // a space of the target's session
  XrPosef pose;   // the target frame in `space`; the orientation must be a unit quaternion
} XrGraspTargetPlacementSDFG;

// Mesh as CPU arrays. The layer copies them; the app keeps ownership.
// vertexCount: number of vertices (xyz float triples in `vertices`), 3..XR_MAX_..._VERTICES;
// indexCount: number of uint32 indices, a multiple of 3, 3..XR_MAX_..._INDICES, each below
// vertexCount. Every coordinate must be finite, and no triangle may repeat an index: each of
// these is XR_ERROR_VALIDATION_FAILURE from the call, on create and on update. Every triangle
// must also have a non-zero area (corners that coincide or are collinear). That rule is checked
// off the app's thread, since it reads every triangle's corners (milliseconds per frame on a mesh
// of a few hundred thousand triangles): a create call whose mesh breaks it succeeds, and the
// target's set-up fails (never graspable; counted in XrGraspTargetsSetupInfoSDFG::failedCount;
// one log line names the triangle); an update whose positions collapse a triangle succeeds, and
// those positions are dropped when they would be applied (the target keeps its last accepted
// shape; one log line per run of such updates).
// Cost on the app's thread: create and update copy the arrays once, with the checks above fused
// into the copy; everything else runs on the session's worker.
// Winding: any. The layer's convention is counter-clockwise (right-handed index order) seen from
// outside, and while it sets the target up (off the app's thread) it detects each connected
// part's orientation (signed volume when the part is closed, the generalized winding number when
// it is open, after making neighbouring triangles consistent) and flips inside-out or mixed parts
// on its own copy; it logs what it found once per target. A flat open sheet is taken as given.
// (Vulkan-buffer targets below are not inspected: wind them counter-clockwise.)
typedef struct XrGraspTargetVerticesSDFG {
  XrStructureType type;  // XR_TYPE_GRASP_TARGET_VERTICES_SDFG
  const void* XR_MAY_ALIAS next;
  uint32_t vertexCount;
  const XrVector3f* vertices;
  uint32_t indexCount;      // on create: required; on update: must be 0 (topology is fixed)
  const uint32_t* indices;  // on update: must be NULL
} XrGraspTargetVerticesSDFG;

#ifdef XR_USE_GRAPHICS_API_VULKAN
// Mesh as Vulkan buffers of the session's VkDevice (a skinned mesh the app already writes on the
// GPU), read by the layer's compute work. The layer reads the mesh back into memory of its own
// (a compute pass on the binding's queue inside xrEndFrame; never a CPU wait in the app's frame)
// and from then on treats it as it treats a mesh given as arrays: exact stops and contacts, a
// member of scenes, seen by the outer hand. After each update naming these buffers it reads the
// positions again (while the target is within half a metre of a hand; farther, once it comes
// near), so what the hands see of a deforming mesh is one readback behind the app's last write:
// a frame or two. The indices are read at creation and when an update names other index
// buffers. Until the first readback is in, the target is grasped on the field the GPU builds
// from the buffers. Only on a
// session created with XrGraphicsBindingVulkanKHR (or ...Vulkan2KHR) whose SDFs are built on the
// GPU; otherwise XR_ERROR_GRAPHICS_DEVICE_INVALID (no Vulkan binding) or
// XR_ERROR_FEATURE_UNSUPPORTED (the session builds on the CPU: gpu = false, no usable device, or
// after a GPU failure).
// - Vertex i's position is 3 floats (x, y, z, metres, target frame) at
//   vertexOffset + i * vertexStride bytes of vertexBuffer; other attributes may sit between.
// - Index k is a uint16 or uint32 (indexType) at indexOffset + k * index size bytes.
// - Both buffers need VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, must be usable on the binding's queue
//   family (exclusive to it, or concurrent), and must stay alive until the target is destroyed
//   (xrDestroyGraspTargetSDFG waits for the layer's reads in flight and returns XR_SUCCESS once
//   they ended; see it for a device that does not end them) or replaced by an update.
// - Writes: the layer reads the buffers in command buffers it submits on the binding's queue
//   inside xrBeginFrame / xrEndFrame. Submit the commands that write them (skinning) on that
//   queue before the xrEndFrame of the frame whose xrSyncActions should see them, and do not
//   write them from another queue without waiting for the frame's work.
// - Index values out of range, and triangles with a non-finite corner, are skipped by the GPU;
//   the read-back mesh leaves out the first kind, and a non-finite corner refuses it (the target
//   is then grasped on its field only; the layer logs either once). Shaders read 32-bit words:
//   a 16-bit index in the last two bytes of a buffer whose size is not a multiple of 4 cannot be
//   read, and its triangle is left out.
// - bounds: an axis-aligned box in the target frame that holds the mesh at all times (for a
//   skinned mesh, over its whole animation): it decides whether the target is in a grab box.
typedef struct XrGraspTargetVulkanBuffersSDFG {
  XrStructureType type;  // XR_TYPE_GRASP_TARGET_VULKAN_BUFFERS_SDFG
  const void* XR_MAY_ALIAS next;
  VkBuffer vertexBuffer;
  VkDeviceSize vertexOffset;  // bytes, a multiple of 4
  uint32_t vertexStride;      // bytes, >= 12 and a multiple of 4
  uint32_t vertexCount;       // 3..XR_MAX_GRASP_TARGET_VERTICES_SDFG
  VkBuffer indexBuffer;
  VkDeviceSize indexOffset;  // bytes, a multiple of the index size
  VkIndexType indexType;     // VK_INDEX_TYPE_UINT16 or VK_INDEX_TYPE_UINT32
  uint32_t indexCount;       // a multiple of 3, 3..XR_MAX_GRASP_TARGET_INDICES_SDFG
  XrVector3f boundsMin;      // target frame, metres; each component <= boundsMax's
  XrVector3f boundsMax;
} XrGraspTargetVulkanBuffersSDFG;
#endif

// Chain exactly one mesh struct (XrGraspTargetVerticesSDFG or XrGraspTargetVulkanBuffersSDFG)
// on `next`: none, two of one kind, or one of each is XR_ERROR_VALIDATION_FAILURE. Structs of
// other types on the chain are ignored.
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
  XrBool32 inContact;       // it stopped on the held target's surface (XR_FALSE: it closes
                            // without touching, or rests on another target, see version 3)
  XrVector3f contactPoint;  // target frame: centre of the touching sphere (any part of the finger,
                            // not only its tip; see version 2 below); zero without inContact
  float distance;           // signed distance of the target at contactPoint (about the radius of
                            // the finger there); zero without inContact
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

// Where a grab-box SDF was built.
typedef enum XrGraspSdfBackendSDFG {
  XR_GRASP_SDF_BACKEND_NONE_SDFG = 0,    // nothing built (not grasping)
  XR_GRASP_SDF_BACKEND_CPU_SDFG = 1,     // the layer's CPU builder
  XR_GRASP_SDF_BACKEND_VULKAN_SDFG = 2,  // compute work on the session's Vulkan device
  XR_GRASP_SDF_BACKEND_MAX_ENUM_SDFG = 0x7FFFFFFF
} XrGraspSdfBackendSDFG;

// Optional output, chained on XrGraspStateSDFG::next: where the SDFs of the session are built.
typedef struct XrGraspBuildInfoSDFG {
  XrStructureType type;  // XR_TYPE_GRASP_BUILD_INFO_SDFG
  void* XR_MAY_ALIAS next;
  XrGraspSdfBackendSDFG graspBackend;  // of the hand's shown grasp; NONE when not grasping
  // Where the session's next build goes: VULKAN once its GPU path is ready (pipelines are made
  // and warmed up in the session's first frames, off the app's calls), CPU before that (a grab
  // then is built on the CPU at once; one of a Vulkan-buffer target waits) and after a failure.
  XrGraspSdfBackendSDFG sessionBackend;
  uint64_t gpuBuildCount;  // builds of the session done on the GPU so far
  uint64_t cpuBuildCount;  // and on the CPU
  XrBool32 gpuFailed;  // the GPU path failed (device lost or any Vulkan error): CPU from then on
  uint32_t pendingGpuBuilds;  // GPU builds requested and not yet collected (0..2)
} XrGraspBuildInfoSDFG;

// Optional output, chained on XrGraspStateSDFG::next: the set-up of the session's targets.
// xrCreateGraspTargetSDFG with CPU arrays checks and copies the mesh and returns; the exact
// distance structure (BVH, pseudo-normals) is built on the layer's worker thread, and the target
// can be grasped only once it is ready (a squeeze before that grabs nothing). A set-up that
// fails (the mesh was refused, or memory ran out) is logged once and leaves the target never
// graspable. A Vulkan buffer target counts as pending until the layer has read its mesh back
// and set it up (it can be grasped meanwhile, on its grab-box field); it is ready at once where
// its mesh cannot be read back.
typedef struct XrGraspTargetsSetupInfoSDFG {
  XrStructureType type;  // XR_TYPE_GRASP_TARGETS_SETUP_INFO_SDFG
  void* XR_MAY_ALIAS next;
  uint32_t readyCount;    // targets of the session that can be grasped
  uint32_t pendingCount;  // targets whose set-up is queued or running
  uint32_t failedCount;   // targets whose set-up failed
} XrGraspTargetsSetupInfoSDFG;

// Solver strategies; the layer's configuration picks the default.
typedef enum XrGraspSolverSDFG {
  XR_GRASP_SOLVER_DEFAULT_SDFG = 0,  // the configured strategy (see docs/layer.md)
  XR_GRASP_SOLVER_PAPER_SDFG = 1,    // the paper's per-finger tip sweep
  XR_GRASP_SOLVER_OURS_SDFG = 2,     // whole-finger, conservative advancement, refined stop
  XR_GRASP_SOLVER_MAX_ENUM_SDFG = 0x7FFFFFFF
} XrGraspSolverSDFG;

// Options of one session, applied from the next grab. Each call sets every field of this struct
// (a zero field: the layer's default); the option structs chained on `next`
// (XrGraspClearanceOptionsSDFG, XrGraspOuterHandOptionsSDFG) that a call leaves out keep the
// values an earlier call gave them.
typedef struct XrGraspOptionsSDFG {
  XrStructureType type;  // XR_TYPE_GRASP_OPTIONS_SDFG
  const void* XR_MAY_ALIAS next;
  XrGraspSolverSDFG solver;
  // The stop distance, metres: a finger stops where the target's distance at its fingertip's
  // centre falls to this (0 = each finger's own tip radius, so the fingertip's surface touches;
  // larger stops it that far off). Named for what it defaults to; else in (0, 0.05].
  float tipRadius;
  XrPosef boxPose;      // grab box centre and axes in the wrist joint's frame (ignored when
                        // boxSize is zero)
  XrVector3f boxSize;   // edge lengths x y z in metres, each in (0, 1]; all zero = default
  uint32_t resolution;  // nodes per axis, 0 or 2..128
  float curlStep;       // curl step along each finger's curve, 0 or (1e-5, 1] (1e-5 excluded)
  float grabThreshold;  // squeeze that starts a grab, 0 or (0, 1]; release is 0.8 of it
} XrGraspOptionsSDFG;

// Registers a graspable mesh on `session`; writes `target` only on success.
// Errors: HANDLE_INVALID (session; placement.space), VALIDATION_FAILURE (createInfo or target
// null; a wrong `type` on createInfo, placement or the mesh struct; not exactly one mesh struct;
// a chain too long; any rule of the mesh struct the call checks broken (see
// XrGraspTargetVerticesSDFG for the zero-area rule, checked by the set-up); a non-finite
// placement pose),
// POSE_INVALID (placement orientation), GRAPHICS_DEVICE_INVALID and FEATURE_UNSUPPORTED (Vulkan
// buffers, see XrGraspTargetVulkanBuffersSDFG), OUT_OF_MEMORY, RUNTIME_FAILURE.
typedef XrResult(XRAPI_PTR* PFN_xrCreateGraspTargetSDFG)(
    XrSession session, const XrGraspTargetCreateInfoSDFG* createInfo, XrGraspTargetSDFG* target);
// Removes `target`; a hand holding it lets go. Errors: HANDLE_INVALID (null, destroyed, or its
// session destroyed). A target in Vulkan buffers: the call first waits for the layer's reads of
// the buffers in flight (at most 2 s for each build, and as long for a GPU call of another
// thread to end), so the app may free them once it returns XR_SUCCESS. RUNTIME_FAILURE when a read
// still runs after that (a hung device): nothing changed, the target stays valid (placed, held
// if it was), the buffers must stay alive, and the app may destroy it again later.
typedef XrResult(XRAPI_PTR* PFN_xrDestroyGraspTargetSDFG)(XrGraspTargetSDFG target);
// New vertex positions (same count, same topology): animated and skinned meshes. Pass an
// XrGraspTargetVerticesSDFG with indexCount 0 and indices NULL (array targets), or an
// XrGraspTargetVulkanBuffersSDFG (buffer targets: the app says its buffers changed; the
// buffers, offsets, stride, index type and bounds may change, the counts may not). A held target
// is solved again from the next xrSyncActions.
// Errors: HANDLE_INVALID (target), VALIDATION_FAILURE (vertices null; its `type` neither mesh
// struct; the wrong kind for the target; another vertex or index count; indexCount or indices
// set on arrays; a non-finite coordinate; any rule of XrGraspTargetVulkanBuffersSDFG broken; a
// chain too long; positions that give a triangle zero area are dropped later, see
// XrGraspTargetVerticesSDFG), FEATURE_UNSUPPORTED (a buffer target
// after the session's GPU path failed), OUT_OF_MEMORY, RUNTIME_FAILURE.
typedef XrResult(XRAPI_PTR* PFN_xrUpdateGraspTargetVerticesSDFG)(XrGraspTargetSDFG target,
                                                                 const void* vertices);
// Moves `target` to another space of its session, or another pose. Errors: HANDLE_INVALID
// (target; placement->space), VALIDATION_FAILURE (placement null, wrong `type`, non-finite pose,
// a chain too long), POSE_INVALID (orientation), RUNTIME_FAILURE.
typedef XrResult(XRAPI_PTR* PFN_xrSetGraspTargetPlacementSDFG)(
    XrGraspTargetSDFG target, const XrGraspTargetPlacementSDFG* placement);
// Fills `state` (and an XrGraspBuildInfoSDFG chained on it) for one hand. Errors:
// HANDLE_INVALID (session), VALIDATION_FAILURE (getInfo or state null or of the wrong `type`;
// hand neither XR_HAND_LEFT_EXT nor XR_HAND_RIGHT_EXT; a chain too long on either),
// RUNTIME_FAILURE.
typedef XrResult(XRAPI_PTR* PFN_xrGetGraspStateSDFG)(XrSession session,
                                                     const XrGraspStateGetInfoSDFG* getInfo,
                                                     XrGraspStateSDFG* state);
// Sets the session's options, from the next grab. Errors: HANDLE_INVALID (session),
// VALIDATION_FAILURE (options null or of the wrong `type`; solver not one of the listed values;
// a field outside its range, NaN included; boxPose non-finite or farther than 1 m from the wrist
// when boxSize is set; a chain too long), POSE_INVALID (boxPose orientation when boxSize is
// set), FEATURE_UNSUPPORTED (XR_GRASP_SOLVER_OURS_SDFG in a build without it),
// OUT_OF_MEMORY, RUNTIME_FAILURE.
typedef XrResult(XRAPI_PTR* PFN_xrSetGraspOptionsSDFG)(XrSession session,
                                                       const XrGraspOptionsSDFG* options);

// ---------------------------------------------------------------------------------------------
// Version 2: honest contacts, the held pose, grasp events, per-target settings.
//
// Every version 1 struct keeps its layout; a version 1 app runs unchanged. Two version 1 fields
// are made honest: XrGraspFingerStateSDFG::contactPoint is the centre of the sphere that touches,
// whichever joint's or bone's it is (with the whole-finger solver often a pad or a proximal
// phalanx, not the fingertip), and XrGraspFingerStateSDFG::distance is the target's signed
// distance at that centre (for targets with a CPU mesh: the exact distance of the mesh, within
// 0.1 mm; for Vulkan buffer targets: the grab-box field's, see XrGraspFingerContactSDFG).
// Structure type values of version 2: 1009900010..1009900039.
// ---------------------------------------------------------------------------------------------

#define XR_TYPE_GRASP_CONTACTS_SDFG ((XrStructureType)1009900010)
#define XR_TYPE_GRASP_HELD_POSE_SDFG ((XrStructureType)1009900011)
#define XR_TYPE_EVENT_DATA_GRASP_CHANGED_SDFG ((XrStructureType)1009900012)
#define XR_TYPE_GRASP_TARGET_SETTINGS_SDFG ((XrStructureType)1009900013)

// The part of a finger that touches. The layer models each finger as spheres along its bones
// (radii interpolated between the joints' XrHandJointLocationEXT::radius).
typedef enum XrGraspContactPartSDFG {
  XR_GRASP_CONTACT_PART_NONE_SDFG = 0,          // the finger touches nothing
  XR_GRASP_CONTACT_PART_JOINT_SPHERE_SDFG = 1,  // the sphere of `joint` (a tip: the fingertip)
  XR_GRASP_CONTACT_PART_BONE_CAPSULE_SDFG = 2,  // a point of the capsule of the bone from `joint`
                                                // to the next joint toward the tip
  XR_GRASP_CONTACT_PART_MAX_ENUM_SDFG = 0x7FFFFFFF
} XrGraspContactPartSDFG;

// Where one finger touches. All points and vectors are in the target frame (the frame of the
// target's vertices, metres), at the solve whose curls the returned joints show; everything is
// zero when part is XR_GRASP_CONTACT_PART_NONE_SDFG. The fields agree with each other:
// surfacePoint is the closest point of the target's surface to sphereCenter, surfaceNormal the
// outward unit normal there, and distance the signed distance at sphereCenter (|distance| is the
// length from sphereCenter to surfacePoint). For targets with a CPU mesh (isExact true) they come
// from one exact query of the mesh: distance equals the mesh's exact signed distance at
// sphereCenter within 0.1 mm (its sign is the side of the mesh's nearest sheet, which on a mesh
// with holes can differ from an inside/outside test right next to a hole). Vulkan buffer targets
// are exact too once the layer has read their mesh back; before that, or where it refused the
// read-back mesh (isExact false), they come from the grab-box signed distance field the layer
// built (trilinear value and gradient), off by up to the field's error: about a millimetre at the
// default 16^3 resolution, several near sharp edges and thin parts.
typedef struct XrGraspFingerContactSDFG {
  XrGraspContactPartSDFG part;
  XrHandJointEXT joint;      // JOINT_SPHERE: the joint; BONE_CAPSULE: the bone's first joint
  float boneFraction;        // BONE_CAPSULE: where along the bone, 0 at `joint` .. 1; else 0
  float sphereRadius;        // metres: the finger's radius at the touching point
  XrVector3f sphereCenter;   // target frame: the touching sphere's centre (= contactPoint)
  XrVector3f surfacePoint;   // target frame: the closest point of the target's surface
  XrVector3f surfaceNormal;  // target frame, unit: the surface's outward normal at surfacePoint
  float distance;            // metres, signed (negative inside) at sphereCenter; about
                             // sphereRadius when the finger rests on the surface
  XrBool32 isExact;          // from the exact mesh distance (XR_FALSE: from the SDF field)
} XrGraspFingerContactSDFG;

// Optional output, chained on XrGraspStateSDFG::next. Fingers in thumb, index, middle, ring,
// little order; all parts NONE when the hand is not grasping.
typedef struct XrGraspContactsSDFG {
  XrStructureType type;  // XR_TYPE_GRASP_CONTACTS_SDFG
  void* XR_MAY_ALIAS next;
  XrGraspFingerContactSDFG fingers[XR_GRASP_FINGER_COUNT_SDFG];
} XrGraspContactsSDFG;

// Optional output, chained on XrGraspStateSDFG::next: where the held target is relative to the
// hand, to attach it. palmFromTarget is the pose of the target frame in the frame of the hand's
// XR_HAND_JOINT_PALM_EXT joint (metres), as the grasp the returned joints show was solved: to
// carry the target, place it at (palm joint pose located at any time) * palmFromTarget. `time`
// is the XrTime the hand and target poses of that solve were located at (the predicted display
// time of the frame whose xrSyncActions solved it). isValid is XR_FALSE (and the pose identity,
// time 0) when the hand is not grasping.
typedef struct XrGraspHeldPoseSDFG {
  XrStructureType type;  // XR_TYPE_GRASP_HELD_POSE_SDFG
  void* XR_MAY_ALIAS next;
  XrBool32 isValid;
  XrPosef palmFromTarget;
  XrTime time;
} XrGraspHeldPoseSDFG;

// Why a grasp changed.
typedef enum XrGraspChangeReasonSDFG {
  XR_GRASP_CHANGE_REASON_GRABBED_SDFG = 1,   // a grasp began: its first solved pose is applied
  XR_GRASP_CHANGE_REASON_RELEASED_SDFG = 2,  // the grab input was released (squeeze below the
                                             // release threshold), the hand was lost or the
                                             // solve failed
  XR_GRASP_CHANGE_REASON_TARGET_DESTROYED_SDFG = 3,  // the app destroyed the held target
  XR_GRASP_CHANGE_REASON_MAX_ENUM_SDFG = 0x7FFFFFFF
} XrGraspChangeReasonSDFG;

// An event returned by xrPollEvent (only to apps that enabled XR_SDFG_auto_grasp) when a hand's
// grasp starts or ends, that is when xrGetGraspStateSDFG's isGrasping changes. It fits in
// XrEventDataBuffer. Order: the layer keeps its events in a queue per instance (the oldest are
// dropped beyond 64) and interleaves them with the runtime's by time: a layer event is returned
// before a runtime event only when its `time` is earlier than the runtime event's own time
// (XrEventDataSessionStateChanged::time, XrEventDataReferenceSpaceChangePending::changeTime,
// XrEventDataInstanceLossPending::lossTime); runtime events without a time come first. Events of
// a session are dropped when it is destroyed.
typedef struct XrEventDataGraspChangedSDFG {
  XrStructureType type;  // XR_TYPE_EVENT_DATA_GRASP_CHANGED_SDFG
  const void* XR_MAY_ALIAS next;
  XrSession session;
  XrHandEXT hand;
  XrGraspTargetSDFG target;  // the target grasped or let go (a destroyed one's former handle)
  XrBool32 isGrasping;       // XR_TRUE: the grasp began; XR_FALSE: it ended
  XrGraspChangeReasonSDFG reason;
  XrTime time;  // the predicted display time of the frame in which it changed
} XrEventDataGraspChangedSDFG;

// Which hands may grasp a target.
typedef XrFlags64 XrGraspHandFlagsSDFG;
static const XrGraspHandFlagsSDFG XR_GRASP_HAND_LEFT_BIT_SDFG = 0x00000001;
static const XrGraspHandFlagsSDFG XR_GRASP_HAND_RIGHT_BIT_SDFG = 0x00000002;

// Settings of one target: chained on XrGraspTargetCreateInfoSDFG::next (without it a target is
// graspable by both hands), or changed with xrSetGraspTargetSettingsSDFG (from the next
// xrSyncActions; a hand holding the target that may no longer grasp it lets go, with a
// XR_GRASP_CHANGE_REASON_RELEASED_SDFG event).
// A target a hand may not grasp is still there for that hand: its fingers stop on it (version 3;
// see "Scenes" below for which target a grab takes when several are in the grab box).
typedef struct XrGraspTargetSettingsSDFG {
  XrStructureType type;  // XR_TYPE_GRASP_TARGET_SETTINGS_SDFG
  const void* XR_MAY_ALIAS next;
  // XR_GRASP_HAND_LEFT_BIT_SDFG, XR_GRASP_HAND_RIGHT_BIT_SDFG, both, or 0: not graspable for now.
  // Other bits: XR_ERROR_VALIDATION_FAILURE.
  XrGraspHandFlagsSDFG graspableBy;
} XrGraspTargetSettingsSDFG;

// Changes a target's settings. Errors: XR_ERROR_HANDLE_INVALID (target),
// XR_ERROR_VALIDATION_FAILURE (null, wrong type, unknown bits in graspableBy); nothing changes
// then.
typedef XrResult(XRAPI_PTR* PFN_xrSetGraspTargetSettingsSDFG)(
    XrGraspTargetSDFG target, const XrGraspTargetSettingsSDFG* settings);

// ---- Version 3 (first published in a version 2 header): never inside ------------------------
// The hand's clearance and offset. These two structs appeared in the header while it still said
// version 2, without a version change; they belong to version 3: a layer that reports
// XR_SDFG_auto_grasp_SPEC_VERSION 3 or more honours them. Added after the version 1 structs, which
// keep their layout. Structure types continue in the extension's range at 1009900040.
#define XR_TYPE_GRASP_HAND_OFFSET_SDFG ((XrStructureType)1009900040)
#define XR_TYPE_GRASP_CLEARANCE_OPTIONS_SDFG ((XrStructureType)1009900041)

// A three-way switch for options whose zero keeps the layer's default.
typedef enum XrGraspSwitchSDFG {
  XR_GRASP_SWITCH_DEFAULT_SDFG = 0,  // the layer's configuration decides
  XR_GRASP_SWITCH_OFF_SDFG = 1,
  XR_GRASP_SWITCH_ON_SDFG = 2,
  XR_GRASP_SWITCH_MAX_ENUM_SDFG = 0x7FFFFFFF
} XrGraspSwitchSDFG;

// Optional output, chained on XrGraspStateSDFG::next: how far the layer moved the hand off the
// tracked (or controller-driven) pose so that no part of it is inside the held object, nor (with
// the outer hand, XrGraspOuterHandOptionsSDFG) inside any target, in every frame. Every one of the
// 26 joints xrLocateHandJointsEXT returns is moved by `offset`: a joint's shown pose is
// trackedWrist * offset * (trackedWrist^-1 * jointPose), with trackedWrist the wrist joint as
// tracked (or as the layer synthesizes it from the grip pose); fingers the outer hand stops on a
// surface are curled less besides. An app that draws its own controller or arm applies the same
// `offset` to it in the wrist frame to follow the hand. The fields other than `offset` describe
// the grasp's own correction (the outer hand's is `offset` composed before it).
typedef struct XrGraspHandOffsetSDFG {
  XrStructureType type;  // XR_TYPE_GRASP_HAND_OFFSET_SDFG
  void* XR_MAY_ALIAS next;
  XrPosef offset;        // the shown wrist in the tracked wrist's frame (identity: not moved)
  XrPosef solvedOffset;  // the whole correction of the current grasp; `offset` blends toward it
                         // at a grab and back to identity after the release
  float blend;           // 0..1: how much of solvedOffset (or, released, of the last) is shown
  float openClearance;   // metres: the open hand's smallest part clearance before the correction
                         // (negative: part of it was inside); 0 when not grasping
  float displacement;    // metres: largest motion of any part of the hand by solvedOffset
  XrBool32 exceeded;     // the hand needed more than the bound: it was not moved
} XrGraspHandOffsetSDFG;

// Optional input, chained on XrGraspOptionsSDFG::next. A zero field keeps the layer's default.
typedef struct XrGraspClearanceOptionsSDFG {
  XrStructureType type;  // XR_TYPE_GRASP_CLEARANCE_OPTIONS_SDFG
  const void* XR_MAY_ALIAS next;
  XrGraspSwitchSDFG clearance;  // move the open hand out of the object before the fingers close
  float maxCorrection;          // metres, 0 or (0, 0.2]: a hand that needs more is not moved
  XrGraspSwitchSDFG approach;   // bring a palm near the surface onto it first
  float approachRange;          // metres, 0 or (0, 0.2]: palms farther than this are left
  float approachMaxAngle;       // radians, 0 or (0, pi]: palms turned farther are left
  float blendTime;              // seconds, 0 or (0, 2]: the offset's blend in and out
} XrGraspClearanceOptionsSDFG;

// ---------------------------------------------------------------------------------------------
// Version 3, a target's own state: whether it is placed.
//
// Every version 1 and 2 struct keeps its layout; version 1 and 2 apps run unchanged (what a
// destroyed space does to the targets placed in it, below, holds for them too). Structure type
// values of this part: 1009900060..1009900069.
// ---------------------------------------------------------------------------------------------

#define XR_TYPE_GRASP_TARGET_STATE_SDFG ((XrStructureType)1009900060)

// Output: the state of one target.
// A target is placed by xrCreateGraspTargetSDFG and xrSetGraspTargetPlacementSDFG. When the app
// destroys the space it is placed in (xrDestroySpace), it is no longer placed: the layer never
// locates it again (it never passes the destroyed space to the runtime), no hand grabs it, and a
// hand holding it lets go at once (an XrEventDataGraspChangedSDFG with
// XR_GRASP_CHANGE_REASON_RELEASED_SDFG). It keeps its mesh and settings, and takes part again from
// the next xrSyncActions after xrSetGraspTargetPlacementSDFG places it in a live space.
typedef struct XrGraspTargetStateSDFG {
  XrStructureType type;  // XR_TYPE_GRASP_TARGET_STATE_SDFG
  void* XR_MAY_ALIAS next;
  XrBool32 isPlaced;  // XR_FALSE: its space was destroyed; it takes no part until placed again
} XrGraspTargetStateSDFG;

// Fills `state` for `target`. Errors: XR_ERROR_HANDLE_INVALID (target),
// XR_ERROR_VALIDATION_FAILURE (state null or of the wrong `type`, a chain too long),
// XR_ERROR_RUNTIME_FAILURE; `state` is not written then.
typedef XrResult(XRAPI_PTR* PFN_xrGetGraspTargetStateSDFG)(XrGraspTargetSDFG target,
                                                           XrGraspTargetStateSDFG* state);

// ---------------------------------------------------------------------------------------------
// Version 3, scenes: every target in the grab box takes part; roles; analytic shapes; touches.
//
// What a grasp sees: every target whose bounds overlap the hand's grab box (the bounds are the
// mesh's axis-aligned bounding box in the target frame, XrGraspTargetVulkanBuffersSDFG's bounds,
// or the shape's, placed where the target is; a plane reaches the box when the box reaches below
// it), except targets whose role is IGNORED. The fingers close on all of them at once: every part
// of the hand stops on the first surface it meets, whoever owns it, and the hand's clearance
// (XrGraspHandOffsetSDFG) keeps it out of all of them. The layer finds the targets near a hand
// through a broad phase over their bounds (a tree per space), so a session may register
// thousands.
//
// Which target a grab takes (the rule, deterministic). A finger touches the target that owns the
// nearest surface at its touching sphere; the palm touches a target whose surface is within 2 cm
// of the palm joint's sphere, and the target it faces (the first surface on the ray from the palm
// joint along the palm's normal, within 30 cm) within 3 cm (a flat object under the palm, a comb
// on a table, is often touched by no finger: they close past it onto the table). Among the
// targets in the grab box that the hand may take (role GRASPABLE and, for that hand,
// XrGraspTargetSettingsSDFG::graspableBy):
//   1. the one the palm faces, if the hand touches it (a finger, or the palm within 3 cm):
//      fingers that wrap past it onto a neighbour (a mug beside a mug, a spoon standing in a mug)
//      do not outvote what the palm is turned to;
//   2. else, among those the hand touches, the one the most fingers touch;
//   3. between those, the one whose surface is nearest the palm joint's centre (exact distance);
//   4. between those, the one created first.
// A target the hand does not touch is never taken (one behind another, say). While the fingers
// touch only targets the hand may not take (a table, a wall, a target of the other hand), the hand
// holds nothing: its fingers rest on what they touch (xrLocateHandJointsEXT shows them closed
// there; XrGraspTouchesSDFG says on what), isGrasping stays XR_FALSE, and the first solve whose
// fingers touch a graspable target takes it. A grasp keeps its target until it ends. Up to version
// 2 the rule was the target whose bounds' centre was nearest the grab box's centre.
//
// Every version 1 and 2 struct keeps its layout, and their apps run unchanged: their targets are
// GRASPABLE, and a target they made not graspable by a hand (graspableBy) now stops that hand's
// fingers instead of being passed through. Structure type values of this part:
// 1009900050..1009900059.
// ---------------------------------------------------------------------------------------------

#define XR_TYPE_GRASP_TARGET_ROLE_SDFG ((XrStructureType)1009900050)
#define XR_TYPE_GRASP_TARGET_SHAPE_SDFG ((XrStructureType)1009900051)
#define XR_TYPE_GRASP_TOUCHES_SDFG ((XrStructureType)1009900052)
#define XR_TYPE_GRASP_OUTER_HAND_OPTIONS_SDFG ((XrStructureType)1009900053)

// What a target is to the hands.
typedef enum XrGraspTargetRoleSDFG {
  XR_GRASP_TARGET_ROLE_GRASPABLE_SDFG = 0,  // hands grasp it and stop on it (the default)
  XR_GRASP_TARGET_ROLE_SCENE_SDFG = 1,      // hands stop on it and never take it: tables,
                                            // shelves, walls, a character's body
  XR_GRASP_TARGET_ROLE_IGNORED_SDFG = 2,    // hands pass through it, as if it were not there
  XR_GRASP_TARGET_ROLE_MAX_ENUM_SDFG = 0x7FFFFFFF
} XrGraspTargetRoleSDFG;

// A target's role: chained on XrGraspTargetCreateInfoSDFG::next (without it: GRASPABLE, and SCENE
// for a plane), or on
// XrGraspTargetSettingsSDFG::next given to xrSetGraspTargetSettingsSDFG (from the next
// xrSyncActions; a hand holding a target that is no longer GRASPABLE lets go, with a
// XR_GRASP_CHANGE_REASON_RELEASED_SDFG event). A role outside the listed values:
// XR_ERROR_VALIDATION_FAILURE, and nothing changes.
typedef struct XrGraspTargetRoleInfoSDFG {
  XrStructureType type;  // XR_TYPE_GRASP_TARGET_ROLE_SDFG
  const void* XR_MAY_ALIAS next;
  XrGraspTargetRoleSDFG role;
} XrGraspTargetRoleInfoSDFG;

// Simple solids a target can be instead of a mesh.
typedef enum XrGraspShapeTypeSDFG {
  // A box centred on the target frame's origin, edges along its axes (halfExtents).
  XR_GRASP_SHAPE_TYPE_BOX_SDFG = 1,
  // The target frame's y = 0 plane, solid below it (its outward normal is +Y): a floor, or a wall
  // placed with +Y toward the room. halfExtents must be zero. Its role is SCENE unless the app
  // chains another (XrGraspTargetRoleInfoSDFG): a floor registered without a role is never taken.
  XR_GRASP_SHAPE_TYPE_PLANE_SDFG = 2,
  XR_GRASP_SHAPE_TYPE_MAX_ENUM_SDFG = 0x7FFFFFFF
} XrGraspShapeTypeSDFG;

// A target that is an analytic shape: chain it on XrGraspTargetCreateInfoSDFG::next as the
// target's one mesh struct (instead of XrGraspTargetVerticesSDFG or ...VulkanBuffersSDFG). Its
// distance is exact and cheap, and it is ready at once (no set-up). Scene geometry is often no
// more than this; a shape may also be GRASPABLE (a box on a table). It cannot be updated with
// xrUpdateGraspTargetVerticesSDFG (XR_ERROR_VALIDATION_FAILURE): destroy and create it again to
// resize it.
typedef struct XrGraspTargetShapeSDFG {
  XrStructureType type;  // XR_TYPE_GRASP_TARGET_SHAPE_SDFG
  const void* XR_MAY_ALIAS next;
  XrGraspShapeTypeSDFG shapeType;
  // BOX: half the edge lengths along the target frame's x, y, z, metres, each finite and in
  // (0, 1000]; PLANE: (0, 0, 0). Anything else: XR_ERROR_VALIDATION_FAILURE.
  XrVector3f halfExtents;
} XrGraspTargetShapeSDFG;

// Optional input, chained on XrGraspOptionsSDFG::next: the outer hand. In every frame, squeezed or
// not, the hand xrLocateHandJointsEXT returns stays outside every target near it (role GRASPABLE
// or SCENE; IGNORED targets and targets in the app's Vulkan buffers are not seen): a tracked hand
// that enters a target is shown stopped on its surface, sliding along it, found from where it was
// shown last so it never crosses a thin part; a finger pressed onto a surface stops on it; a held
// target counts as part of the hand (kept out of the others). While the tracked hand is clear of
// everything the shown hand is the tracked hand exactly, and while no target is near the joints
// pass through bit-identical. When the tracked hand is more than releaseDistance from the shown
// one, the shown hand returns to tracking over blendTime and holds again once the tracked hand is
// clear. The whole-hand offset is reported in every frame by XrGraspHandOffsetSDFG::offset.
// On by default (the layer configuration's outer_hand); docs/layer.md says why. Applied from the
// next xrSyncActions. A zero field keeps the layer's default.
typedef struct XrGraspOuterHandOptionsSDFG {
  XrStructureType type;  // XR_TYPE_GRASP_OUTER_HAND_OPTIONS_SDFG
  const void* XR_MAY_ALIAS next;
  XrGraspSwitchSDFG outerHand;  // keep the shown hand out of the targets in every frame
  float releaseDistance;        // metres, 0 or (0, 1]: the shown hand returns to tracking past it
  float blendTime;              // seconds, 0 or (0, 2]: how long that return takes
} XrGraspOuterHandOptionsSDFG;

// Optional output, chained on XrGraspStateSDFG::next: what the hand's fingers touch, held or not.
typedef struct XrGraspTouchesSDFG {
  XrStructureType type;  // XR_TYPE_GRASP_TOUCHES_SDFG
  void* XR_MAY_ALIAS next;
  // The hand's fingers rest on solved poses: a grab is on (the squeeze is held and a solve is
  // shown), whether it holds a target (isGrasping) or only rests on targets it may not take.
  XrBool32 isClosed;
  // Per finger (thumb, index, middle, ring, little), the target its contact is on;
  // XR_NULL_HANDLE where the finger touches nothing (or the hand is not closed). A finger on a
  // target other than the held one has no contact anywhere else: it is not inContact in
  // XrGraspFingerStateSDFG and its part is NONE in XrGraspContactsSDFG (both describe the held
  // target, in its frame).
  XrGraspTargetSDFG touched[XR_GRASP_FINGER_COUNT_SDFG];
} XrGraspTouchesSDFG;

// Optional output, chained on XrGraspStateSDFG::next: the depth scene near the hand (docs/depth.md;
// config depth_scene). A grab closes on what the app drew only once `ready`; one that starts
// before closes on what else is there.
#define XR_TYPE_GRASP_DEPTH_SCENE_INFO_SDFG ((XrStructureType)1009900070)
typedef struct XrGraspDepthSceneInfoSDFG {
  XrStructureType type;  // XR_TYPE_GRASP_DEPTH_SCENE_INFO_SDFG
  void* XR_MAY_ALIAS next;
  XrBool32 enabled;     // this session reads the depth the app submits
  uint32_t framesRead;  // frames of the app's depth handed to the scene so far
  XrBool32 ready;       // the depth around this hand holds a fused frame: fingers stop on it
} XrGraspDepthSceneInfoSDFG;

// The depth scene (docs/depth.md, config depth_scene = on): what XrGraspStateSDFG::target,
// XrGraspTouchesSDFG::touched[] and XrEventDataGraspChangedSDFG::target hold for what the layer
// knows only from the depth the app submits (XR_KHR_composition_layer_depth). Not a handle: no
// function takes it, and it never equals one the layer hands out.
#define XR_GRASP_TARGET_DEPTH_SCENE_SDFG ((XrGraspTargetSDFG)(uint64_t)0x4000000000000000ull)

#ifdef __cplusplus
}
#endif

#endif  // XR_SDFG_AUTO_GRASP_H_
