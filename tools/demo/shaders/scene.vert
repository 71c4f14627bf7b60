#version 450
// Scene vertices: world position, normal (zero length: unlit marker), colour.
layout(location = 0) in vec3 inPosition;
layout(location = 1) in vec3 inNormal;
layout(location = 2) in vec3 inColour;

layout(push_constant) uniform Push {
  mat4 viewProjection;
  vec4 lightDirection;  // world space, toward the light
} push;

layout(location = 0) out vec3 outNormal;
layout(location = 1) out vec3 outColour;

void main() {
  gl_Position = push.viewProjection * vec4(inPosition, 1.0);
  outNormal = inNormal;
  outColour = inColour;
}
