#version 450
// Lambert with one fixed light and an ambient term; zero normals mark unlit geometry (contacts).
layout(push_constant) uniform Push {
  mat4 viewProjection;
  vec4 lightDirection;
} push;

layout(location = 0) in vec3 inNormal;
layout(location = 1) in vec3 inColour;
layout(location = 0) out vec4 outColour;

void main() {
  if (dot(inNormal, inNormal) < 1e-8) {
    outColour = vec4(inColour, 1.0);
    return;
  }
  // Two-sided: open meshes show their back faces, lit as seen.
  float lambert = abs(dot(normalize(inNormal), normalize(push.lightDirection.xyz)));
  outColour = vec4(inColour * (0.3 + 0.7 * lambert), 1.0);
}
