// grasp_scene.c: an OpenXR app that uses the SDF Autograsp layer's extension, XR_SDFG_auto_grasp,
// in one file of plain C. Start here.
//
// It registers a small scene (a table top that hands only stop on, a cup and a block that hands
// may take), runs frames, and prints what the right hand holds and what each finger touches. The
// layer closes the hand onto whatever it reaches when the user squeezes; the app reads the hand
// with the ordinary xrLocateHandJointsEXT and asks the layer what it holds.
//
// Run it on the project's headless mock runtime with a scripted controller, as `ctest -R
// example_grasp_scene` does, with these variables set:
//   XR_RUNTIME_JSON=build/default/tests/mock_runtime/sdfg_mock_runtime.json
//   XR_API_LAYER_PATH=build/default/layer/explicit
//   XR_ENABLE_API_LAYERS=XR_APILAYER_SDFG_autograsp
//   SDFG_MOCK_HAND_TRACKING=absent (a controller-only runtime: the layer synthesizes the hand)
//   SDFG_MOCK_SCRIPT=examples/grasp_scene.script
// then build/default/examples/grasp_scene.
// It creates a headless session (XR_MND_headless) so that it runs anywhere; a real app creates its
// session with its graphics binding and does everything else the same way.
#if !defined(_WIN32)
#define _POSIX_C_SOURCE 200809L  // nanosleep
#endif
#include <math.h>
#include <stdio.h>
#include <string.h>
#if defined(_WIN32)
#include <windows.h>
#else
#include <time.h>
#endif

#include <openxr/openxr.h>

#include <openxr/XR_SDFG_auto_grasp.h>

#define CHECK_XR(call)                                                 \
  do {                                                                 \
    XrResult r_ = (call);                                              \
    if (XR_FAILED(r_)) {                                               \
      fprintf(stderr, "grasp_scene: %s failed: %d\n", #call, (int)r_); \
      return 1;                                                        \
    }                                                                  \
  } while (0)

// A real runtime's xrWaitFrame blocks until the next frame (11 ms apart at 90 Hz); the mock
// runtime answers at once, so the example waits itself, as an app's frame would take. The
// layer's grasps are solved on its own thread meanwhile.
static void waitForNextFrame(void) {
#if defined(_WIN32)
  Sleep(11);
#else
  const struct timespec frame = {0, 11 * 1000 * 1000};
  nanosleep(&frame, NULL);
#endif
}

// The extension's functions, fetched with xrGetInstanceProcAddr like any extension's.
typedef struct Grasp {
  PFN_xrCreateGraspTargetSDFG createTarget;
  PFN_xrDestroyGraspTargetSDFG destroyTarget;
  PFN_xrGetGraspStateSDFG getState;
  PFN_xrCreateHandTrackerEXT createHandTracker;
  PFN_xrDestroyHandTrackerEXT destroyHandTracker;
  PFN_xrLocateHandJointsEXT locateHandJoints;
} Grasp;

// A cup: a closed octagonal prism, 3 cm in radius and 9 cm tall, standing on its base (y = 0).
enum { kSides = 8 };
static XrVector3f cupVertices[2 * kSides + 2];
static uint32_t cupIndices[4 * kSides * 3];

static void makeCup(void) {
  const float radius = 0.03f, height = 0.09f;
  for (int i = 0; i < kSides; ++i) {
    const float a = 2.0f * 3.14159265f * (float)i / kSides;
    cupVertices[i] = (XrVector3f){radius * cosf(a), 0.0f, radius * sinf(a)};
    cupVertices[kSides + i] = (XrVector3f){radius * cosf(a), height, radius * sinf(a)};
  }
  cupVertices[2 * kSides] = (XrVector3f){0.0f, 0.0f, 0.0f};        // base centre
  cupVertices[2 * kSides + 1] = (XrVector3f){0.0f, height, 0.0f};  // top centre
  uint32_t* t = cupIndices;
  for (uint32_t i = 0; i < kSides; ++i) {
    const uint32_t j = (i + 1) % kSides;
    // Counter-clockwise seen from outside (the layer would also fix either winding).
    *t++ = i, *t++ = kSides + i, *t++ = j;                        // side
    *t++ = j, *t++ = kSides + i, *t++ = kSides + j;               // side
    *t++ = 2 * kSides, *t++ = i, *t++ = j;                        // base
    *t++ = 2 * kSides + 1, *t++ = kSides + j, *t++ = kSides + i;  // top
  }
}

// Registers a target in `space` at `position` (identity orientation): a mesh when `vertices` is
// given, else an analytic box of half extents `half`. `role`: what it is to the hands.
static XrResult makeTarget(const Grasp* g, XrSession session, XrSpace space, XrVector3f position,
                           const XrGraspTargetVerticesSDFG* vertices, XrVector3f half,
                           XrGraspTargetRoleSDFG role, XrGraspTargetSDFG* out) {
  XrGraspTargetShapeSDFG box = {.type = XR_TYPE_GRASP_TARGET_SHAPE_SDFG};
  box.shapeType = XR_GRASP_SHAPE_TYPE_BOX_SDFG;
  box.halfExtents = half;
  XrGraspTargetRoleInfoSDFG roleInfo = {.type = XR_TYPE_GRASP_TARGET_ROLE_SDFG};
  roleInfo.next = vertices != NULL ? (const void*)vertices : (const void*)&box;
  roleInfo.role = role;
  XrGraspTargetCreateInfoSDFG info = {.type = XR_TYPE_GRASP_TARGET_CREATE_INFO_SDFG};
  info.next = &roleInfo;
  info.placement.type = XR_TYPE_GRASP_TARGET_PLACEMENT_SDFG;
  info.placement.space = space;
  info.placement.pose.orientation.w = 1.0f;
  info.placement.pose.position = position;
  return g->createTarget(session, &info, out);
}

int main(void) {
  // 1. An instance with the layer's extension and hand tracking (the layer provides hand tracking
  //    where the runtime has only controllers).
  const char* extensions[] = {XR_SDFG_AUTO_GRASP_EXTENSION_NAME,
                              XR_EXT_HAND_TRACKING_EXTENSION_NAME, XR_MND_HEADLESS_EXTENSION_NAME};
  XrInstanceCreateInfo ici = {.type = XR_TYPE_INSTANCE_CREATE_INFO};
  strcpy(ici.applicationInfo.applicationName, "grasp_scene");
  ici.applicationInfo.apiVersion = XR_MAKE_VERSION(1, 0, 0);
  ici.enabledExtensionCount = 3;
  ici.enabledExtensionNames = extensions;
  XrInstance instance = XR_NULL_HANDLE;
  CHECK_XR(xrCreateInstance(&ici, &instance));

  Grasp g;
  CHECK_XR(xrGetInstanceProcAddr(instance, "xrCreateGraspTargetSDFG",
                                 (PFN_xrVoidFunction*)&g.createTarget));
  CHECK_XR(xrGetInstanceProcAddr(instance, "xrDestroyGraspTargetSDFG",
                                 (PFN_xrVoidFunction*)&g.destroyTarget));
  CHECK_XR(
      xrGetInstanceProcAddr(instance, "xrGetGraspStateSDFG", (PFN_xrVoidFunction*)&g.getState));
  CHECK_XR(xrGetInstanceProcAddr(instance, "xrCreateHandTrackerEXT",
                                 (PFN_xrVoidFunction*)&g.createHandTracker));
  CHECK_XR(xrGetInstanceProcAddr(instance, "xrDestroyHandTrackerEXT",
                                 (PFN_xrVoidFunction*)&g.destroyHandTracker));
  CHECK_XR(xrGetInstanceProcAddr(instance, "xrLocateHandJointsEXT",
                                 (PFN_xrVoidFunction*)&g.locateHandJoints));

  // 2. A session, a LOCAL space, a tracker of the right hand.
  XrSystemGetInfo sgi = {.type = XR_TYPE_SYSTEM_GET_INFO};
  sgi.formFactor = XR_FORM_FACTOR_HEAD_MOUNTED_DISPLAY;
  XrSystemId system = XR_NULL_SYSTEM_ID;
  CHECK_XR(xrGetSystem(instance, &sgi, &system));
  XrSessionCreateInfo sci = {.type = XR_TYPE_SESSION_CREATE_INFO};
  sci.systemId = system;  // headless: no graphics binding on `next`
  XrSession session = XR_NULL_HANDLE;
  CHECK_XR(xrCreateSession(instance, &sci, &session));
  XrReferenceSpaceCreateInfo rsci = {.type = XR_TYPE_REFERENCE_SPACE_CREATE_INFO};
  rsci.referenceSpaceType = XR_REFERENCE_SPACE_TYPE_LOCAL;
  rsci.poseInReferenceSpace.orientation.w = 1.0f;
  XrSpace local = XR_NULL_HANDLE;
  CHECK_XR(xrCreateReferenceSpace(session, &rsci, &local));
  XrHandTrackerCreateInfoEXT htci = {.type = XR_TYPE_HAND_TRACKER_CREATE_INFO_EXT};
  htci.hand = XR_HAND_RIGHT_EXT;
  htci.handJointSet = XR_HAND_JOINT_SET_DEFAULT_EXT;
  XrHandTrackerEXT rightHand = XR_NULL_HANDLE;
  CHECK_XR(g.createHandTracker(session, &htci, &rightHand));

  // 2b. The app's own input, as every app has: an action set, attached once and synced every
  //     frame. The layer's own set (the controller's squeeze and grip) goes with it, and its grab
  //     update runs in that sync. The layer never attaches a set alone, since the app may attach
  //     only once per session: until the app attaches, no controller can be read and hands
  //     synthesized from one are not active.
  XrActionSetCreateInfo asci = {.type = XR_TYPE_ACTION_SET_CREATE_INFO};
  strcpy(asci.actionSetName, "grasp_scene");
  strcpy(asci.localizedActionSetName, "Grasp scene");
  XrActionSet actionSet = XR_NULL_HANDLE;
  CHECK_XR(xrCreateActionSet(instance, &asci, &actionSet));
  XrActionCreateInfo aci = {.type = XR_TYPE_ACTION_CREATE_INFO};
  aci.actionType = XR_ACTION_TYPE_BOOLEAN_INPUT;
  strcpy(aci.actionName, "menu");
  strcpy(aci.localizedActionName, "Menu");
  XrAction menu = XR_NULL_HANDLE;
  CHECK_XR(xrCreateAction(actionSet, &aci, &menu));
  XrPath profile = XR_NULL_PATH, menuClick = XR_NULL_PATH;
  CHECK_XR(xrStringToPath(instance, "/interaction_profiles/oculus/touch_controller", &profile));
  CHECK_XR(xrStringToPath(instance, "/user/hand/left/input/menu/click", &menuClick));
  XrActionSuggestedBinding binding = {menu, menuClick};
  XrInteractionProfileSuggestedBinding suggested = {
      .type = XR_TYPE_INTERACTION_PROFILE_SUGGESTED_BINDING};
  suggested.interactionProfile = profile;
  suggested.countSuggestedBindings = 1;
  suggested.suggestedBindings = &binding;
  CHECK_XR(xrSuggestInteractionProfileBindings(instance, &suggested));
  XrSessionActionSetsAttachInfo attach = {.type = XR_TYPE_SESSION_ACTION_SETS_ATTACH_INFO};
  attach.countActionSets = 1;
  attach.actionSets = &actionSet;
  CHECK_XR(xrAttachSessionActionSets(session, &attach));

  // 3. The scene, in LOCAL (metres): a table top 40 cm below the head whose hands only stop on
  //    it; a cup standing on it; a block beside the cup, 16 cm away.
  const char* names[3] = {"table", "cup", "block"};
  XrGraspTargetSDFG targets[3] = {XR_NULL_HANDLE, XR_NULL_HANDLE, XR_NULL_HANDLE};
  makeCup();
  XrGraspTargetVerticesSDFG cup = {.type = XR_TYPE_GRASP_TARGET_VERTICES_SDFG};
  cup.vertexCount = 2 * kSides + 2;
  cup.vertices = cupVertices;
  cup.indexCount = 4 * kSides * 3;
  cup.indices = cupIndices;
  const XrVector3f none = {0, 0, 0};
  CHECK_XR(makeTarget(&g, session, local, (XrVector3f){0.2f, -0.42f, -0.4f}, NULL,
                      (XrVector3f){0.5f, 0.02f, 0.5f}, XR_GRASP_TARGET_ROLE_SCENE_SDFG,
                      &targets[0]));
  CHECK_XR(makeTarget(&g, session, local, (XrVector3f){0.22f, -0.4f, -0.4f}, &cup, none,
                      XR_GRASP_TARGET_ROLE_GRASPABLE_SDFG, &targets[1]));
  CHECK_XR(makeTarget(&g, session, local, (XrVector3f){0.38f, -0.375f, -0.4f}, NULL,
                      (XrVector3f){0.025f, 0.025f, 0.025f}, XR_GRASP_TARGET_ROLE_GRASPABLE_SDFG,
                      &targets[2]));

  // 4. Frames. The session begins when the runtime says READY and ends when it says STOPPING.
  int running = 1, begun = 0, heldCup = 0, frame = 0;
  XrGraspTargetSDFG lastHeld = XR_NULL_HANDLE;
  while (running) {
    XrEventDataBuffer event = {.type = XR_TYPE_EVENT_DATA_BUFFER};
    while (xrPollEvent(instance, &event) == XR_SUCCESS) {
      if (event.type == XR_TYPE_EVENT_DATA_SESSION_STATE_CHANGED) {
        const XrEventDataSessionStateChanged* e = (const XrEventDataSessionStateChanged*)&event;
        if (e->state == XR_SESSION_STATE_READY) {
          XrSessionBeginInfo sbi = {.type = XR_TYPE_SESSION_BEGIN_INFO};
          sbi.primaryViewConfigurationType = XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO;
          CHECK_XR(xrBeginSession(session, &sbi));
          begun = 1;
        } else if (e->state == XR_SESSION_STATE_STOPPING) {
          CHECK_XR(xrEndSession(session));
          begun = 0;
        } else if (e->state == XR_SESSION_STATE_EXITING) {
          running = 0;
        }
      } else if (event.type == XR_TYPE_EVENT_DATA_GRASP_CHANGED_SDFG) {
        // The layer's own event: a grasp began or ended.
        const XrEventDataGraspChangedSDFG* e = (const XrEventDataGraspChangedSDFG*)&event;
        printf("frame %d: %s hand %s a target\n", frame,
               e->hand == XR_HAND_RIGHT_EXT ? "right" : "left",
               e->isGrasping ? "took" : "let go of");
      }
      event.type = XR_TYPE_EVENT_DATA_BUFFER;
    }
    if (!begun) continue;

    XrFrameState fs = {.type = XR_TYPE_FRAME_STATE};
    waitForNextFrame();
    CHECK_XR(xrWaitFrame(session, NULL, &fs));
    CHECK_XR(xrBeginFrame(session, NULL));
    XrActiveActionSet active = {actionSet, XR_NULL_PATH};
    XrActionsSyncInfo sync = {.type = XR_TYPE_ACTIONS_SYNC_INFO};
    sync.countActiveActionSets = 1;
    sync.activeActionSets = &active;
    CHECK_XR(xrSyncActions(session, &sync));  // XR_SESSION_NOT_FOCUSED is a success

    // The hand as the app draws it: the ordinary joints, closed onto the cup once grasped.
    XrHandJointLocationEXT joints[XR_HAND_JOINT_COUNT_EXT];
    XrHandJointLocationsEXT locations = {.type = XR_TYPE_HAND_JOINT_LOCATIONS_EXT};
    locations.jointCount = XR_HAND_JOINT_COUNT_EXT;
    locations.jointLocations = joints;
    XrHandJointsLocateInfoEXT hli = {.type = XR_TYPE_HAND_JOINTS_LOCATE_INFO_EXT};
    hli.baseSpace = local;
    hli.time = fs.predictedDisplayTime;
    CHECK_XR(g.locateHandJoints(rightHand, &hli, &locations));

    // What the hand holds, and what each finger touches (version 3).
    XrGraspTouchesSDFG touches = {.type = XR_TYPE_GRASP_TOUCHES_SDFG};
    XrGraspStateSDFG state = {.type = XR_TYPE_GRASP_STATE_SDFG};
    state.next = &touches;
    XrGraspStateGetInfoSDFG gsi = {.type = XR_TYPE_GRASP_STATE_GET_INFO_SDFG};
    gsi.hand = XR_HAND_RIGHT_EXT;
    CHECK_XR(g.getState(session, &gsi, &state));
    const XrGraspTargetSDFG held = state.isGrasping ? state.target : XR_NULL_HANDLE;
    if (held != lastHeld) {
      lastHeld = held;
      const char* what = "nothing";
      for (int i = 0; i < 3; ++i)
        if (held == targets[i]) what = names[i];
      printf("frame %d: the right hand holds: %s\n", frame, what);
      if (held == targets[1]) heldCup = 1;
      static const char* fingers[] = {"thumb", "index", "middle", "ring", "little"};
      for (int f = 0; f < XR_GRASP_FINGER_COUNT_SDFG && touches.isClosed; ++f) {
        const char* on = "nothing";
        for (int i = 0; i < 3; ++i)
          if (touches.touched[f] == targets[i]) on = names[i];
        printf("  %s touches %s (curl %.2f)\n", fingers[f], on, (double)state.fingers[f].curl);
      }
    }

    XrFrameEndInfo fei = {.type = XR_TYPE_FRAME_END_INFO};
    fei.displayTime = fs.predictedDisplayTime;
    fei.environmentBlendMode = XR_ENVIRONMENT_BLEND_MODE_OPAQUE;
    CHECK_XR(xrEndFrame(session, &fei));
    ++frame;
  }

  for (int i = 0; i < 3; ++i) CHECK_XR(g.destroyTarget(targets[i]));
  CHECK_XR(g.destroyHandTracker(rightHand));
  CHECK_XR(xrDestroySpace(local));
  CHECK_XR(xrDestroySession(session));
  CHECK_XR(xrDestroyActionSet(actionSet));
  CHECK_XR(xrDestroyInstance(instance));
  // The example's own check (ctest runs it): the hand took the cup at some point.
  printf(heldCup ? "grasp_scene: the right hand took the cup\n"
                 : "grasp_scene: the right hand never took the cup\n");
  return heldCup ? 0 : 2;
}
