#include "render/render.hpp"

#include "render/gl_api.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <initializer_list>
#include <stdexcept>

#include "math/errors.hpp"
#include "render/offscreen.hpp"

namespace arcsim {

namespace {

// Look of the image. Colours are linear 0..1 RGB(A) as OpenGL takes them.
constexpr GLfloat kBackgroundTop[3] = {0.98f, 0.985f, 0.99f};
constexpr GLfloat kBackgroundBottom[3] = {0.80f, 0.82f, 0.85f};
constexpr GLfloat kGroundLight[3] = {0.92f, 0.925f, 0.93f};
constexpr GLfloat kGroundDark[3] = {0.87f, 0.875f, 0.88f};
constexpr GLfloat kShadow[4] = {0.0f, 0.0f, 0.02f, 0.30f};
constexpr GLfloat kClothFront[4] = {0.97f, 0.62f, 0.34f, 1.0f};
constexpr GLfloat kClothBack[4] = {0.46f, 0.55f, 0.70f, 1.0f};
constexpr GLfloat kObstacle[4] = {0.72f, 0.72f, 0.72f, 1.0f};
constexpr GLfloat kHighlight[4] = {0.16f, 0.09f, 0.05f, 1.0f};
constexpr GLfloat kWire[4] = {0.12f, 0.06f, 0.02f, 0.35f};

// One mesh in the form glDrawElements wants, built once per frame and reused by every pass.
struct MeshArrays {
  std::vector<GLfloat> positions, normals;  // 3 per vertex
  std::vector<GLuint> triangles, highlight, wire;
  bool casts_shadow = true;
};

// Per-vertex normals: the sum of the adjacent faces' cross products, i.e. area-weighted face normals, so that
// slivers from remeshing do not bias the shading.
MeshArrays prepare(const RenderMesh& mesh, bool wireframe, bool highlight, const Stage& stage) {
  MeshArrays a;
  const size_t n = mesh.positions.size();
  std::vector<Vec3> normal_sum(n, Vec3::Zero());
  a.triangles.reserve(3 * mesh.triangles.size());
  for (const auto& t : mesh.triangles) {
    const Vec3& p0 = mesh.positions[t[0]];
    const Vec3 face = (mesh.positions[t[1]] - p0).cross(mesh.positions[t[2]] - p0);
    for (int v : t) {
      normal_sum[v] += face;
      a.triangles.push_back(GLuint(v));
    }
  }
  a.positions.resize(3 * n);
  a.normals.resize(3 * n);
  double highest = -kInfinity;
  for (size_t i = 0; i < n; ++i) {
    const double len = normal_sum[i].norm();
    const Vec3 unit = len > 0 ? Vec3(normal_sum[i] / len) : stage.up;
    for (int k = 0; k < 3; ++k) {
      a.positions[3 * i + k] = GLfloat(mesh.positions[i][k]);
      a.normals[3 * i + k] = GLfloat(unit[k]);
    }
    highest = std::max(highest, stage.up.dot(mesh.positions[i]));
  }
  // A floor lying on the ground would project its shadow onto itself and darken all of it.
  a.casts_shadow = highest - stage.ground_level > 1e-3 * stage.scene_radius;
  if (highlight)
    for (const auto& e : mesh.highlight_edges) a.highlight.insert(a.highlight.end(), {GLuint(e[0]), GLuint(e[1])});
  if (wireframe)
    for (const auto& e : unique_edges(mesh.triangles)) a.wire.insert(a.wire.end(), {GLuint(e[0]), GLuint(e[1])});
  return a;
}

void set_vertex_arrays(const MeshArrays& a, bool with_normals) {
  gl().EnableClientState(GL_VERTEX_ARRAY);
  gl().VertexPointer(3, GL_FLOAT, 0, a.positions.data());
  if (with_normals) {
    gl().EnableClientState(GL_NORMAL_ARRAY);
    gl().NormalPointer(GL_FLOAT, 0, a.normals.data());
  } else {
    gl().DisableClientState(GL_NORMAL_ARRAY);
  }
}

void draw_triangles(const MeshArrays& a, bool with_normals) {
  if (a.triangles.empty()) return;
  set_vertex_arrays(a, with_normals);
  gl().DrawElements(GL_TRIANGLES, GLsizei(a.triangles.size()), GL_UNSIGNED_INT, a.triangles.data());
}

void draw_lines(const MeshArrays& a, const std::vector<GLuint>& lines) {
  if (lines.empty()) return;
  set_vertex_arrays(a, false);
  gl().DrawElements(GL_LINES, GLsizei(lines.size()), GL_UNSIGNED_INT, lines.data());
}

void set_material(GLenum face, const GLfloat colour[4], GLfloat specular, GLfloat shininess) {
  const GLfloat spec[4] = {specular, specular, specular, 1};
  gl().Materialfv(face, GL_AMBIENT_AND_DIFFUSE, colour);
  gl().Materialfv(face, GL_SPECULAR, spec);
  gl().Materialf(face, GL_SHININESS, shininess);
}

void set_light(GLenum light, const Vec3& toward, GLfloat diffuse, GLfloat specular) {
  const GLfloat position[4] = {GLfloat(toward.x()), GLfloat(toward.y()), GLfloat(toward.z()), 0};  // directional
  const GLfloat zero[4] = {0, 0, 0, 1};
  const GLfloat dif[4] = {diffuse, diffuse, diffuse, 1};
  const GLfloat spec[4] = {specular, specular, specular, 1};
  gl().Enable(light);
  gl().Lightfv(light, GL_POSITION, position);  // transformed by the current (view) matrix: world direction
  gl().Lightfv(light, GL_AMBIENT, zero);
  gl().Lightfv(light, GL_DIFFUSE, dif);
  gl().Lightfv(light, GL_SPECULAR, spec);
}

void draw_background() {
  gl().MatrixMode(GL_PROJECTION);
  gl().LoadIdentity();
  gl().MatrixMode(GL_MODELVIEW);
  gl().LoadIdentity();
  gl().Disable(GL_DEPTH_TEST);
  gl().Disable(GL_LIGHTING);
  gl().Begin(GL_QUADS);
  gl().Color3fv(kBackgroundBottom);
  gl().Vertex2f(-1, -1);
  gl().Vertex2f(1, -1);
  gl().Color3fv(kBackgroundTop);
  gl().Vertex2f(1, 1);
  gl().Vertex2f(-1, 1);
  gl().End();
}

double smoothstep(double edge0, double edge1, double x) {
  const double t = std::clamp((x - edge0) / (edge1 - edge0), 0.0, 1.0);
  return t * t * (3 - 2 * t);
}

// Checkered square around the scene, aligned with world units, fading into the background towards its border.
void draw_ground(const Stage& stage) {
  const HorizontalAxes axes = horizontal_axes(stage.up);
  double cell = checker_cell_size(stage.scene_radius);
  const double radius = stage.ground_radius;
  while (2 * radius / cell > 200) cell *= 2;  // bounded work whatever the scene size
  // Slightly below the lowest point, so sheets resting there do not fight with the ground for depth.
  const Vec3 origin = stage.up * (stage.ground_level - 2e-3 * stage.scene_radius);
  const double ca = stage.ground_center.dot(axes.side), cb = stage.ground_center.dot(axes.front);
  const long i0 = long(std::floor((ca - radius) / cell)), i1 = long(std::ceil((ca + radius) / cell));
  const long j0 = long(std::floor((cb - radius) / cell)), j1 = long(std::ceil((cb + radius) / cell));
  gl().Begin(GL_QUADS);
  for (long i = i0; i < i1; ++i)
    for (long j = j0; j < j1; ++j) {
      const GLfloat* c = ((i + j) & 1) ? kGroundDark : kGroundLight;
      // Alpha carries the fade, which differs per corner.
      auto corner = [&](long ii, long jj) {
        const double a = double(ii) * cell, b = double(jj) * cell;
        const double fade = 1 - smoothstep(0.35 * radius, radius, std::hypot(a - ca, b - cb));
        gl().Color4f(c[0], c[1], c[2], GLfloat(fade));
        const Vec3 p = origin + a * axes.side + b * axes.front;
        gl().Vertex3d(p.x(), p.y(), p.z());
      };
      corner(i, j);
      corner(i + 1, j);
      corner(i + 1, j + 1);
      corner(i, j + 1);
    }
  gl().End();
}

// Resets the state a previous frame may have left and paints the background gradient.
void clear_to_background(int width, int height, bool multisampled) {
  gl().Viewport(0, 0, width, height);
  gl().Disable(GL_SCISSOR_TEST);
  gl().ColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  gl().DepthMask(GL_TRUE);
  gl().StencilMask(0xff);
  gl().ClearColor(kBackgroundTop[0], kBackgroundTop[1], kBackgroundTop[2], 1);
  gl().ClearDepth(1);
  gl().ClearStencil(0);
  gl().Clear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT | GL_STENCIL_BUFFER_BIT);
  if (multisampled) gl().Enable(GL_MULTISAMPLE);
  gl().ShadeModel(GL_SMOOTH);
  gl().Disable(GL_CULL_FACE);
  gl().Disable(GL_STENCIL_TEST);
  gl().Disable(GL_BLEND);
  gl().Disable(GL_POLYGON_OFFSET_FILL);
  draw_background();
}

// Loads the camera's projection and view (returned) and enables depth testing. The clipping planes hug
// everything that can be drawn (the ground reaches beyond the scene), for depth precision.
Mat4 load_camera(const Camera& camera, const Stage& stage, const Eigen::AlignedBox3d& box, bool ground,
                 double aspect) {
  const double reach = std::max(stage.scene_radius, ground ? std::sqrt(2.0) * stage.ground_radius : 0.0);
  const double distance = (camera.eye - box.center()).norm();
  const double z_far = std::max(distance + 1.05 * reach, 1e-6);
  const double z_near = std::max(z_far * 1e-3, distance - 1.05 * reach);
  const Mat4 projection = projection_matrix(camera, aspect, z_near, z_far);
  const Mat4 view = view_matrix(camera);
  gl().MatrixMode(GL_PROJECTION);
  gl().LoadMatrixd(projection.data());
  gl().MatrixMode(GL_MODELVIEW);
  gl().LoadMatrixd(view.data());
  gl().Enable(GL_DEPTH_TEST);
  gl().DepthFunc(GL_LEQUAL);
  return view;
}

// Two-sided lighting: back faces are lit with the reversed normal and the back material. Needs the view matrix
// loaded (light directions are given in world space).
void set_lights(const Stage& stage) {
  const GLfloat ambient[4] = {0.30f, 0.30f, 0.30f, 1};
  gl().LightModelfv(GL_LIGHT_MODEL_AMBIENT, ambient);
  gl().LightModeli(GL_LIGHT_MODEL_TWO_SIDE, GL_TRUE);
  gl().LightModeli(GL_LIGHT_MODEL_LOCAL_VIEWER, GL_FALSE);
  set_light(GL_LIGHT0, stage.key_light, 0.72f, 0.25f);
  set_light(GL_LIGHT1, stage.fill_light, 0.30f, 0.0f);
  gl().Color4f(1, 1, 1, 1);
}

// Darkens the ground and obstacle pixels (stencil 1) covered by the meshes flattened onto the ground along the
// key light; each pixel once (stencil becomes 2). Pulled forward so it wins against a floor obstacle lying in the
// ground plane, while anything standing in front of the plane still hides it.
void draw_shadows(const Stage& stage, const Mat4& view,
                  std::initializer_list<const std::vector<MeshArrays>*> casters) {
  gl().StencilFunc(GL_EQUAL, 1, 0xff);
  gl().StencilOp(GL_KEEP, GL_KEEP, GL_INCR);
  gl().DepthMask(GL_FALSE);
  gl().Enable(GL_BLEND);
  gl().BlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
  gl().Color4fv(kShadow);
  gl().PolygonOffset(-1, -4);
  const Mat4 shadow = view * planar_shadow_matrix(stage.up, stage.ground_level, stage.key_light);
  gl().LoadMatrixd(shadow.data());
  for (const auto* list : casters)
    for (const MeshArrays& a : *list)
      if (a.casts_shadow) draw_triangles(a, false);
  gl().LoadMatrixd(view.data());
  gl().Disable(GL_BLEND);
  gl().DepthMask(GL_TRUE);
}

// Wireframe and highlighted edges of the cloths. Lines sit exactly on the surfaces, which were pushed back by
// the polygon offset, so they win the depth test where the surface is visible.
void draw_edges(const std::vector<MeshArrays>& cloths, const RenderOptions& options, int image_height) {
  const GLfloat line_scale = GLfloat(std::max(1.0, image_height / 720.0));
  if (options.wireframe) {
    gl().Enable(GL_BLEND);
    gl().BlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
    gl().DepthMask(GL_FALSE);
    gl().LineWidth(line_scale);
    gl().Color4fv(kWire);
    for (const MeshArrays& a : cloths) draw_lines(a, a.wire);
    gl().DepthMask(GL_TRUE);
    gl().Disable(GL_BLEND);
  }
  if (options.highlight_edges) {
    gl().LineWidth(2 * line_scale);
    gl().Color4fv(kHighlight);
    for (const MeshArrays& a : cloths) draw_lines(a, a.highlight);
  }
  gl().DisableClientState(GL_VERTEX_ARRAY);
  gl().DisableClientState(GL_NORMAL_ARRAY);
}

std::string gl_error_text(GLenum error) {
  char text[32];
  std::snprintf(text, sizeof text, "0x%04x", unsigned(error));
  return text;
}

}  // namespace

Renderer::Renderer(int width, int height)
    : context_(std::make_unique<OffscreenContext>(width, height)), width_(width), height_(height) {
  rgba_.assign(size_t(width) * size_t(height) * 4, 0);
}

Renderer::~Renderer() = default;

void Renderer::render(const std::vector<RenderMesh>& cloths, const std::vector<RenderMesh>& obstacles,
                      const Camera& camera, const RenderOptions& options) {
  for (size_t i = 0; i < cloths.size(); ++i) check_render_mesh(cloths[i], "render: cloth " + std::to_string(i));
  for (size_t i = 0; i < obstacles.size(); ++i)
    check_render_mesh(obstacles[i], "render: obstacle " + std::to_string(i));

  Eigen::AlignedBox3d box = bounds_of(cloths).extend(bounds_of(obstacles));
  if (!options.scene_bounds.isEmpty() && options.scene_bounds.min().allFinite() &&
      options.scene_bounds.max().allFinite())
    box.extend(options.scene_bounds);
  // The ground stays where the whole animation's lowest point is, even when this frame's meshes are higher.
  const Vec3 up = up_from_gravity(-options.up);  // unit, with a fallback for a zero vector
  const Eigen::AlignedBox3d level_box = options.scene_bounds.isEmpty() ? box : options.scene_bounds;
  const double level = options.ground_level && std::isfinite(*options.ground_level)
                           ? *options.ground_level
                           : (level_box.isEmpty() ? kInfinity : lowest_level(level_box, up));
  const Stage stage = make_stage(camera, up, box, level);

  std::vector<MeshArrays> cloth_arrays, obstacle_arrays;
  for (const RenderMesh& m : cloths)
    cloth_arrays.push_back(prepare(m, options.wireframe, options.highlight_edges, stage));
  for (const RenderMesh& m : obstacles) obstacle_arrays.push_back(prepare(m, false, false, stage));

  const bool multisampled = context_->begin_frame(options.samples);
  clear_to_background(width_, height_, multisampled);
  const Mat4 view = load_camera(camera, stage, box, options.ground, double(width_) / double(height_));
  set_lights(stage);

  // Ground and obstacles mark the stencil buffer: shadows are drawn only there, once per pixel.
  gl().Enable(GL_STENCIL_TEST);
  gl().StencilFunc(GL_ALWAYS, 1, 0xff);
  gl().StencilOp(GL_KEEP, GL_KEEP, GL_REPLACE);
  gl().Enable(GL_POLYGON_OFFSET_FILL);
  if (options.ground) {
    gl().Enable(GL_BLEND);
    gl().BlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
    gl().PolygonOffset(4, 16);  // behind everything resting on it
    draw_ground(stage);
    gl().Disable(GL_BLEND);
  }
  gl().Enable(GL_LIGHTING);
  set_material(GL_FRONT_AND_BACK, kObstacle, 0.12f, 20);
  gl().PolygonOffset(2, 4);  // behind cloth lying on them
  for (const MeshArrays& a : obstacle_arrays) draw_triangles(a, true);
  gl().Disable(GL_LIGHTING);
  if (options.ground && options.shadows) draw_shadows(stage, view, {&obstacle_arrays, &cloth_arrays});
  gl().Disable(GL_STENCIL_TEST);

  gl().Enable(GL_LIGHTING);
  set_material(GL_FRONT, kClothFront, 0.15f, 28);
  set_material(GL_BACK, kClothBack, 0.10f, 28);
  gl().PolygonOffset(1, 1);  // lets the lines drawn next win the depth test
  for (const MeshArrays& a : cloth_arrays) draw_triangles(a, true);
  gl().Disable(GL_LIGHTING);
  gl().Disable(GL_POLYGON_OFFSET_FILL);
  draw_edges(cloth_arrays, options, height_);

  context_->end_frame();
  const GLenum error = gl().GetError();
  if (error != GL_NO_ERROR) throw std::runtime_error("renderer: OpenGL error " + gl_error_text(error));

  const size_t row = size_t(width_) * 4;
  for (int y = 0; y < height_; ++y)
    std::memcpy(&rgba_[size_t(y) * row], &context_->pixels()[size_t(height_ - 1 - y) * row], row);
  for (size_t i = 3; i < rgba_.size(); i += 4) rgba_[i] = 255;
}

void render_frame_png(Renderer& renderer, const std::vector<RenderMesh>& cloths,
                      const std::vector<RenderMesh>& obstacles, const Camera& camera, const RenderOptions& options,
                      const std::string& png_path) {
  renderer.render(cloths, obstacles, camera, options);
  write_png(png_path, renderer.width(), renderer.height(), renderer.rgba());
}

}  // namespace arcsim
