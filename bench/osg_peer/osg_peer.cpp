// The OpenSceneGraph peer of Farfield's walkthrough benchmark (scripts/bench_peer_osg.sh): the same scene, loaded
// with Farfield's importer so that objects, meshes and materials are the same, drawn by OpenSceneGraph 3.6 along the
// same camera path at the same size, with a shader of the same cost as Farfield's mesh shader (base colour times
// texture, alpha cut-out, one directional light plus ambient). Per object a transform node whose drawables OSG culls
// against the frustum (its default culling: view frustum, small features, clusters), or, with --mode impostor, an
// osgSim::Impostor over each object (OSG's image-cache impostors: a sprite rendered from the object beyond
// --threshold metres, re-rendered when its error exceeds --pixel-error pixels).
//
//   osg_peer SCENE PATH.json [--size WxH] [--stride K] [--frames N] [--warmup N] [--mode full|impostor]
//            [--threshold M] [--pixel-error PX] [--tag TAG] [--csv FILE] [--window | --egl] [--screenshot FILE.png]
//
// Prints "RESULT tag=... mode=... frames=N median=... p95=... p99=... max=... mean=... first=..." (milliseconds per
// frame: osgViewer::Viewer::frame(), update, cull and draw, through glFinish). Draws into a GLX pbuffer of the display
// (Xvfb where there is none), or with --egl into an EGL pbuffer without any X server (egl_pbuffer.h: a GPU machine).
#include <osg/CullFace>
#include <osg/GL>
#include <osg/Geode>
#include <osg/Geometry>
#include <osg/MatrixTransform>
#include <osg/Program>
#include <osg/Texture2D>
#include <osgSim/Impostor>
#include <osgUtil/CullVisitor>
#include <osgViewer/Renderer>
#include <osgViewer/Viewer>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "farfield/core/error.h"
#include "farfield/gen/camera_path.h"
#include "farfield/image/png_io.h"
#include "farfield/scene/import.h"
#include "egl_pbuffer.h"

namespace {

using farfield::Vec3;

const char* kVertex = R"(#version 130
out vec3 v_normal;
out vec2 v_uv;
out vec3 v_eye_position;
void main() {
  gl_Position = ftransform();
  v_normal = gl_NormalMatrix * gl_Normal;
  v_uv = gl_MultiTexCoord0.xy;
  v_eye_position = (gl_ModelViewMatrix * gl_Vertex).xyz;
}
)";

// mesh.frag.glsl's shading: albedo = base colour (times the texture, cut out below alpha 0.5), lit by one directional
// light plus ambient unless unlit; a missing normal falls back to the face normal.
const char* kFragment = R"(#version 130
in vec3 v_normal;
in vec2 v_uv;
in vec3 v_eye_position;
uniform vec4 u_base_color;
uniform int u_textured;
uniform int u_unlit;
uniform vec3 u_light_eye;  // the direction light travels, in eye space
uniform vec3 u_light_color;
uniform float u_ambient;
uniform sampler2D u_texture;
void main() {
  vec4 albedo = u_base_color;
  if (u_textured != 0) {
    albedo *= texture(u_texture, v_uv);
    if (albedo.a < 0.5) discard;
  }
  vec3 rgb = albedo.rgb;
  if (u_unlit == 0) {
    vec3 n = v_normal;
    if (dot(n, n) < 1e-12) n = cross(dFdx(v_eye_position), dFdy(v_eye_position));
    else if (!gl_FrontFacing) n = -n;
    n = normalize(n);
    rgb *= vec3(u_ambient) + u_light_color * max(dot(n, -u_light_eye), 0.0);
  }
  gl_FragColor = vec4(rgb, albedo.a);
}
)";

struct Args {
  std::string scene, path, mode = "full", tag, csv;
  int width = 640, height = 360;
  size_t stride = 1, frames = 0, warmup = 1;
  float threshold = 100.0f, pixel_error = 4.0f;
  bool window = false;       // a window instead of a pbuffer
  bool egl = false;          // an EGL pbuffer (no X server) instead of GLX's
  std::string screenshot;    // the last frame as a PNG
};

[[noreturn]] void usage(const std::string& why) {
  std::fprintf(stderr, "error: %s\nusage: osg_peer SCENE PATH.json [--size WxH] [--stride K] [--frames N] [--warmup N] "
                       "[--mode full|impostor] [--threshold M] [--pixel-error PX] [--tag TAG] [--csv FILE] "
                       "[--window | --egl] [--screenshot FILE.png]\n",
               why.c_str());
  std::exit(2);
}

Args parseArgs(int argc, char** argv) {
  Args a;
  std::vector<std::string> positional;
  for (int i = 1; i < argc; ++i) {
    const std::string k = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) usage(k + " needs a value");
      return argv[++i];
    };
    if (k == "--size") {
      if (std::sscanf(value().c_str(), "%dx%d", &a.width, &a.height) != 2 || a.width < 1 || a.height < 1)
        usage("--size must be WxH");
    } else if (k == "--stride") {
      a.stride = std::max<size_t>(1, std::stoul(value()));
    } else if (k == "--frames") {
      a.frames = std::stoul(value());
    } else if (k == "--warmup") {
      a.warmup = std::stoul(value());
    } else if (k == "--mode") {
      a.mode = value();
      if (a.mode != "full" && a.mode != "impostor") usage("--mode must be full or impostor");
    } else if (k == "--threshold") {
      a.threshold = std::stof(value());
    } else if (k == "--pixel-error") {
      a.pixel_error = std::stof(value());
    } else if (k == "--tag") {
      a.tag = value();
    } else if (k == "--csv") {
      a.csv = value();
    } else if (k == "--window") {
      a.window = true;
    } else if (k == "--egl") {
      a.egl = true;
    } else if (k == "--screenshot") {
      a.screenshot = value();
    } else if (!k.empty() && k[0] == '-') {
      usage("unknown option " + k);
    } else {
      positional.push_back(k);
    }
  }
  if (positional.size() != 2) usage("give SCENE and PATH.json");
  if (a.window && a.egl) usage("--window and --egl exclude each other");
  a.scene = positional[0];
  a.path = positional[1];
  if (a.tag.empty()) a.tag = a.mode;
  return a;
}

osg::ref_ptr<osg::Geometry> geometryOf(const farfield::scene::Mesh& mesh) {
  osg::ref_ptr<osg::Geometry> g = new osg::Geometry;
  g->setUseDisplayList(false);
  g->setUseVertexBufferObjects(true);
  osg::ref_ptr<osg::Vec3Array> positions = new osg::Vec3Array(mesh.positions.size());
  osg::ref_ptr<osg::Vec3Array> normals = new osg::Vec3Array(mesh.positions.size());
  osg::ref_ptr<osg::Vec2Array> uvs = new osg::Vec2Array(mesh.positions.size());
  for (size_t i = 0; i < mesh.positions.size(); ++i) {
    const Vec3& p = mesh.positions[i];
    (*positions)[i].set(p.x, p.y, p.z);
    const Vec3 n = mesh.normals.empty() ? Vec3(0.0f) : mesh.normals[i];
    (*normals)[i].set(n.x, n.y, n.z);
    if (!mesh.uvs.empty()) (*uvs)[i].set(mesh.uvs[i].x, mesh.uvs[i].y);
  }
  g->setVertexArray(positions);
  g->setNormalArray(normals, osg::Array::BIND_PER_VERTEX);
  g->setTexCoordArray(0, uvs, osg::Array::BIND_PER_VERTEX);
  g->addPrimitiveSet(new osg::DrawElementsUInt(GL_TRIANGLES, GLsizei(mesh.indices.size()), mesh.indices.data()));
  return g;
}

osg::ref_ptr<osg::StateSet> stateOf(const farfield::scene::Material& m) {
  osg::ref_ptr<osg::StateSet> s = new osg::StateSet;
  s->addUniform(new osg::Uniform("u_base_color", osg::Vec4(m.base_color.r, m.base_color.g, m.base_color.b,
                                                            m.base_color.a)));
  s->addUniform(new osg::Uniform("u_unlit", m.unlit ? 1 : 0));
  const bool textured = m.texture && !m.texture->empty();
  s->addUniform(new osg::Uniform("u_textured", textured ? 1 : 0));
  if (textured) {
    osg::ref_ptr<osg::Image> image = new osg::Image;
    const auto& t = *m.texture;
    auto* data = new unsigned char[size_t(t.width()) * size_t(t.height()) * 4];
    std::memcpy(data, t.data(), size_t(t.width()) * size_t(t.height()) * 4);
    image->setImage(t.width(), t.height(), 1, GL_RGBA8, GL_RGBA, GL_UNSIGNED_BYTE, data, osg::Image::USE_NEW_DELETE);
    osg::ref_ptr<osg::Texture2D> texture = new osg::Texture2D(image);
    texture->setWrap(osg::Texture::WRAP_S, osg::Texture::REPEAT);
    texture->setWrap(osg::Texture::WRAP_T, osg::Texture::REPEAT);
    texture->setFilter(osg::Texture::MIN_FILTER, osg::Texture::LINEAR_MIPMAP_LINEAR);
    texture->setFilter(osg::Texture::MAG_FILTER, osg::Texture::LINEAR);
    s->setTextureAttributeAndModes(0, texture, osg::StateAttribute::ON);
  }
  if (m.double_sided) {
    s->setMode(GL_CULL_FACE, osg::StateAttribute::OFF);
  } else {
    s->setAttributeAndModes(new osg::CullFace(osg::CullFace::BACK), osg::StateAttribute::ON);
  }
  return s;
}

// glFinish after the frame's draw, so that the frame's time is the GPU's too.
struct Finish : osg::Camera::DrawCallback {
  void operator()(osg::RenderInfo&) const override { glFinish(); }
};

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const double r = p / 100.0 * double(v.size() - 1);
  const size_t k = size_t(r);
  return k + 1 < v.size() ? v[k] + (r - double(k)) * (v[k + 1] - v[k]) : v[k];
}

}  // namespace

int main(int argc, char** argv) {
  const Args args = parseArgs(argc, argv);
  farfield::scene::Scene scene;
  farfield::gen::CameraPath path;
  const auto load_start = std::chrono::steady_clock::now();
  try {
    scene = farfield::scene::loadScene(args.scene);
    path = farfield::gen::loadCameraPath(args.path);
  } catch (const farfield::Error& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  }

  // ---- the scene graph: one transform per object, its parts as drawables with their material's state ----
  std::vector<osg::ref_ptr<osg::Geometry>> geometries;
  for (const auto& mesh : scene.meshes) geometries.push_back(geometryOf(mesh));
  std::vector<osg::ref_ptr<osg::StateSet>> states;
  for (const auto& material : scene.materials) states.push_back(stateOf(material));
  osg::ref_ptr<osg::StateSet> shading = new osg::StateSet;
  osg::ref_ptr<osg::Program> program = new osg::Program;
  program->addShader(new osg::Shader(osg::Shader::VERTEX, kVertex));
  program->addShader(new osg::Shader(osg::Shader::FRAGMENT, kFragment));
  shading->setAttributeAndModes(program, osg::StateAttribute::ON);
  shading->addUniform(new osg::Uniform("u_texture", 0));
  osg::ref_ptr<osg::Uniform> light_eye = new osg::Uniform("u_light_eye", osg::Vec3(0.0f, 0.0f, -1.0f));
  shading->addUniform(light_eye);
  shading->addUniform(new osg::Uniform("u_light_color", osg::Vec3(1.0f, 0.97f, 0.92f)));  // gpu::LightSettings
  shading->addUniform(new osg::Uniform("u_ambient", 0.35f));
  osg::ref_ptr<osg::Group> root = new osg::Group;
  const bool impostors = args.mode == "impostor";
  // With impostors the shader sits on each object, so that OSG's sprites keep its own texturing.
  if (!impostors) root->setStateSet(shading);
  uint64_t triangles = 0;
  for (const auto& object : scene.objects) {
    osg::ref_ptr<osg::MatrixTransform> node = new osg::MatrixTransform(osg::Matrix(&object.transform[0][0]));
    if (impostors) node->setStateSet(shading);
    for (const auto& part : object.parts) {
      osg::ref_ptr<osg::Geode> geode = new osg::Geode;
      geode->addDrawable(geometries.at(part.mesh));
      geode->setStateSet(states.at(part.material));
      node->addChild(geode);
      triangles += scene.meshes[part.mesh].indices.size() / 3;
    }
    if (impostors) {
      osg::ref_ptr<osgSim::Impostor> impostor = new osgSim::Impostor;
      impostor->addChild(node, 0.0f, 1e7f);
      impostor->setImpostorThreshold(args.threshold);
      root->addChild(impostor);
    } else {
      root->addChild(node);
    }
  }
  const double load_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - load_start).count();

  // ---- a headless viewer: a pbuffer of the frame's size, GLX's or (--egl) EGL's as an embedded window ----
  std::unique_ptr<osg_peer::EglPbuffer> egl;
  osgViewer::Viewer viewer;
  viewer.setThreadingModel(osgViewer::Viewer::SingleThreaded);
  osg::Camera* camera = viewer.getCamera();
  osg::ref_ptr<osg::GraphicsContext> gc;
  if (args.egl) {
    try {
      egl = std::make_unique<osg_peer::EglPbuffer>(args.width, args.height);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "error: %s\n", e.what());
      return 1;
    }
    // The EGL context stays current on this thread: the embedded window's makeCurrent does nothing.
    gc = viewer.setUpViewerAsEmbeddedInWindow(0, 0, args.width, args.height);
  } else {
    osg::ref_ptr<osg::GraphicsContext::Traits> traits = new osg::GraphicsContext::Traits;
    traits->readDISPLAY();
    traits->setUndefinedScreenDetailsToDefaultScreen();
    traits->width = args.width;
    traits->height = args.height;
    traits->pbuffer = !args.window;
    traits->windowDecoration = false;
    traits->doubleBuffer = true;
    traits->red = traits->green = traits->blue = traits->alpha = 8;
    traits->depth = 24;
    gc = osg::GraphicsContext::createGraphicsContext(traits);
    if (!gc) {
      std::fprintf(stderr, "error: no pbuffer of %dx%d (OpenSceneGraph needs a display: run under xvfb-run, or "
                           "give --egl)\n", args.width, args.height);
      return 1;
    }
    camera->setGraphicsContext(gc);
  }
  camera->setViewport(0, 0, args.width, args.height);
  camera->setClearColor(osg::Vec4(0.62f, 0.74f, 0.88f, 1.0f));
  camera->setComputeNearFarMode(osg::CullSettings::DO_NOT_COMPUTE_NEAR_FAR);
  camera->setFinalDrawCallback(new Finish);
  const GLenum buffer = GL_BACK;  // a double-buffered GLX pbuffer's or window's back buffer; an EGL pbuffer's only one
  camera->setDrawBuffer(buffer);
  camera->setReadBuffer(buffer);
  viewer.setSceneData(root);
  viewer.setCameraManipulator(nullptr);
  viewer.realize();
  if (impostors)
    if (auto* renderer = dynamic_cast<osgViewer::Renderer*>(camera->getRenderer()))
      for (unsigned i = 0; i < 2; ++i)
        if (osgUtil::SceneView* view = renderer->getSceneView(i))
          view->getCullVisitor()->setImpostorPixelErrorThreshold(args.pixel_error);

  std::vector<size_t> indices;
  for (size_t i = 0; i < path.frames.size(); i += args.stride) {
    if (args.frames != 0 && indices.size() >= args.frames) break;
    indices.push_back(i);
  }
  const Vec3 light_world = glm::normalize(Vec3(-0.4f, -0.3f, -0.85f));
  std::vector<double> times;
  gc->makeCurrent();
  std::printf("scene: %s objects=%zu tris=%llu impostors=%d load=%.0fms\n", args.scene.c_str(), scene.objects.size(),
              static_cast<unsigned long long>(triangles), impostors ? int(scene.objects.size()) : 0, load_ms);
  std::printf("GL_RENDERER=%s GL_VERSION=%s%s\n", reinterpret_cast<const char*>(glGetString(GL_RENDERER)),
              reinterpret_cast<const char*>(glGetString(GL_VERSION)),
              egl ? (" via " + egl->source()).c_str() : " via GLX");
  gc->releaseContext();
  auto frame = [&](size_t i) {
    const farfield::gen::PathFrame& f = path.frames[i];
    camera->setProjectionMatrixAsPerspective(f.fov_y * 180.0 / M_PI, double(args.width) / double(args.height), 0.5,
                                             20000.0);
    const osg::Matrixd view = osg::Matrixd::lookAt(osg::Vec3d(f.eye.x, f.eye.y, f.eye.z),
                                                   osg::Vec3d(f.at.x, f.at.y, f.at.z),
                                                   osg::Vec3d(f.up.x, f.up.y, f.up.z));
    camera->setViewMatrix(view);
    const osg::Vec3d l = osg::Matrixd::transform3x3(osg::Vec3d(light_world.x, light_world.y, light_world.z), view);
    light_eye->set(osg::Vec3(l) / float(l.length()));
    const auto t0 = std::chrono::steady_clock::now();
    viewer.frame();
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  };
  for (size_t w = 0; w < args.warmup && !indices.empty(); ++w) frame(indices.front());
  for (size_t i : indices) times.push_back(frame(i));
  double mean = 0.0;
  for (double t : times) mean += t;
  mean /= double(std::max<size_t>(times.size(), 1));
  std::printf("RESULT tag=%s mode=%s threshold=%g pixerr=%g frames=%zu median=%.3f p95=%.3f p99=%.3f max=%.3f "
              "mean=%.3f first=%.3f\n",
              args.tag.c_str(), args.mode.c_str(), args.threshold, args.pixel_error, times.size(),
              percentile(times, 50), percentile(times, 95), percentile(times, 99),
              times.empty() ? 0.0 : *std::max_element(times.begin(), times.end()), mean,
              times.empty() ? 0.0 : times.front());
  if (!args.screenshot.empty()) {
    // The last frame, read back (after the timing): evidence that the peer drew the city.
    gc->makeCurrent();
    farfield::image::ColorImage image(args.width, args.height);
    glReadBuffer(buffer);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    std::vector<unsigned char> rows(size_t(args.width) * size_t(args.height) * 4);
    glReadPixels(0, 0, args.width, args.height, GL_RGBA, GL_UNSIGNED_BYTE, rows.data());
    for (int y = 0; y < args.height; ++y)
      std::memcpy(&image.at(0, y), &rows[size_t(args.height - 1 - y) * size_t(args.width) * 4], size_t(args.width) * 4);
    gc->releaseContext();
    farfield::image::writePng(args.screenshot, image);
  }
  if (!args.csv.empty()) {
    std::ofstream csv(args.csv);
    csv << "frame,path_frame,wall_ms\n";
    for (size_t k = 0; k < times.size(); ++k) csv << k << "," << indices[k] << "," << times[k] << "\n";
  }
  return 0;
}
