// computeContacts (grasp/contact.h): the touching part of each finger, its sphere's centre rebuilt
// from the final joint curls, and the exact closest point, signed distance and normal of the
// target's mesh there; the field's answer for targets without a mesh.
#include <catch2/catch.hpp>

#include <cmath>

#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>

#include "grasp/contact.h"
#include "io/shapes.h"
#include "sdf/sdf_cpu.h"

namespace {

using namespace sdfg;

// A grasp whose index finger touches with `bone` at `t`, at per-joint curls `curls`.
GraspResult indexContact(int bone, float t, const JointCurls& curls) {
  GraspResult r;
  FingerState& f = r.fingers[int(Finger::index)];
  f.contact = true;
  f.jointCurls = curls;
  f.contactBone = bone;
  f.contactT = t;
  return r;
}

}  // namespace

TEST_CASE("Contacts: the touching part and the exact answers of the mesh at its sphere",
          "[contact]") {
  const HandModel hand = HandModel::defaultAdult(Hand::right);
  const float radius = 0.04f;
  auto made = MeshDistance::create(makeSphere(radius, 5));
  REQUIRE(made);
  const MeshDistance& mesh = **made;
  const JointCurls curls{0.2f, 0.4f, 0.6f, 0.3f};
  std::array<Pose, 5> poses{};
  hand.fingerPose(Finger::index, curls, std::span(poses.data(), poses.size()));
  // The object's frame: turned and moved so that a frame mix-up shows.
  const Pose objectFromHand{glm::angleAxis(0.4f, glm::normalize(glm::vec3(1, 1, 0))),
                            glm::vec3(0.01f, -0.02f, 0.05f)};

  SECTION("a fingertip sphere") {
    const FingerContacts c =
        computeContacts(hand, indexContact(3, 1.0f, curls), objectFromHand, &mesh, nullptr);
    const FingerContact& k = c[int(Finger::index)];
    REQUIRE(k.valid);
    CHECK(k.exact);
    CHECK(k.jointSphere);
    CHECK(k.joint == Joint::index_tip);
    CHECK(k.radius == Approx(hand.jointRadius(Joint::index_tip)));
    const glm::vec3 expected = objectFromHand.transformPoint(poses[4].position);
    CHECK(glm::length(k.center - expected) < 1e-6f);
    // The sphere's answers (its faces are at most 7 um inside at 5 subdivisions).
    CHECK(k.distance == Approx(glm::length(k.center) - radius).margin(1e-5));
    // On the surface, toward the centre (a flat face's closest point may sit beside the
    // radial one, by the distance times the face's tilt), and |distance| away.
    CHECK(std::abs(glm::length(k.surfacePoint) - radius) < 1e-5f);
    CHECK(glm::dot(glm::normalize(k.surfacePoint), glm::normalize(k.center)) > 0.9995f);
    CHECK(glm::length(k.center - k.surfacePoint) == Approx(std::abs(k.distance)).margin(1e-6));
    CHECK(glm::dot(k.normal, glm::normalize(k.center)) > 0.9995f);
    // The other fingers touch nothing.
    for (int f = 0; f < kFingerCount; ++f)
      if (f != int(Finger::index)) CHECK(!c[f].valid);
  }
  SECTION("a point of a bone's capsule") {
    const FingerContacts c =
        computeContacts(hand, indexContact(2, 0.25f, curls), objectFromHand, &mesh, nullptr);
    const FingerContact& k = c[int(Finger::index)];
    REQUIRE(k.valid);
    CHECK(!k.jointSphere);
    CHECK(k.joint == Joint::index_intermediate);
    CHECK(k.boneFraction == Approx(0.25f));
    const glm::vec3 expected =
        objectFromHand.transformPoint(glm::mix(poses[2].position, poses[3].position, 0.25f));
    CHECK(glm::length(k.center - expected) < 1e-6f);
    CHECK(k.radius == Approx(0.75f * hand.jointRadius(Joint::index_intermediate) +
                             0.25f * hand.jointRadius(Joint::index_distal)));
  }
  SECTION("inside the object the distance is negative and the normal still points out") {
    // Move the object so the fingertip sits 5 mm inside the sphere's surface.
    const glm::vec3 tip = poses[4].position;
    const Pose inside{glm::quat(1, 0, 0, 0), -tip + glm::vec3(radius - 0.005f, 0, 0)};
    const FingerContacts c =
        computeContacts(hand, indexContact(3, 1.0f, curls), inside, &mesh, nullptr);
    const FingerContact& k = c[int(Finger::index)];
    REQUIRE(k.valid);
    CHECK(k.distance == Approx(-0.005f).margin(2e-5));
    CHECK(glm::dot(k.normal, glm::vec3(1, 0, 0)) > 0.999f);
  }
  SECTION("no contact, no bone, or nothing to ask: invalid") {
    GraspResult none;
    CHECK(!computeContacts(hand, none, objectFromHand, &mesh, nullptr)[1].valid);
    CHECK(!computeContacts(hand, indexContact(7, 1.0f, curls), objectFromHand, &mesh, nullptr)[1]
               .valid);
    CHECK(!computeContacts(hand, indexContact(3, 1.0f, curls), objectFromHand, nullptr, nullptr)[1]
               .valid);
  }
}

TEST_CASE("Contacts without a mesh come from the field and say so", "[contact]") {
  const HandModel hand = HandModel::defaultAdult(Hand::right);
  const float radius = 0.04f;
  const TriangleMesh sphere = makeSphere(radius, 4);
  auto made = MeshDistance::create(sphere);
  REQUIRE(made);
  const JointCurls curls{0.2f, 0.4f, 0.6f, 0.3f};
  std::array<Pose, 5> poses{};
  hand.fingerPose(Finger::index, curls, std::span(poses.data(), poses.size()));
  // The sphere centred 4.9 cm from the tip, around the default grab box.
  const GridBox box = GridBox::referenceDefault();
  const glm::vec3 c = poses[4].position + glm::vec3(0.0f, -0.049f, 0.0f);
  const Pose objectFromHand{glm::quat(1, 0, 0, 0), -c};
  SdfGrid grid;
  CpuSdfBuilder builder;
  REQUIRE(builder.build(**made, objectFromHand, box, grid) == Status::ok);
  const FingerContacts contacts =
      computeContacts(hand, indexContact(3, 1.0f, curls), objectFromHand, nullptr, &grid);
  const FingerContact& k = contacts[int(Finger::index)];
  REQUIRE(k.valid);
  CHECK(!k.exact);
  // The 16^3 field's error near a 4 cm sphere: about a millimetre.
  CHECK(k.distance == Approx(0.009f).margin(0.002f));
  CHECK(glm::length(k.center - k.surfacePoint) == Approx(std::abs(k.distance)).margin(1e-5));
  CHECK(glm::dot(k.normal, glm::normalize(k.center)) > 0.95f);
}
