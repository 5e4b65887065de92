// segue render POLICY --task NAME --out FILE.mp4: a video of one deterministic episode.
// Rendering is headless: MuJoCo's OpenGL renderer draws into its offscreen framebuffer
// on an EGL context that has no window and no surface (Mesa's surfaceless platform, so
// no X server or GPU is needed). Frames go to ffmpeg through a pipe, or to PNG files.
#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "algorithms/policy.h"
#include "core/mujoco_env.h"
#include "core/run_dir.h"
#include "core/thread_pool.h"
#include "environments/registry.h"
#include "hrl/composite_recipe.h"
#include "hrl/controller.h"
#include "hrl/skill_recipe.h"
#include "tools/segue/cli.h"

namespace segue::cli {
namespace {

namespace fs = std::filesystem;

const Command kRender{
    "render",
    "[POLICY-or-RECIPE] --task NAME [--method M] --out FILE.mp4 [--frames DIR] [--seed S] ...",
    "Runs the deterministic policy (a checkpoint.pt, an exported .pt, or a recipe .yaml whose\n"
    "run directory has a checkpoint.pt) for one episode and renders it headless (EGL). With\n"
    "--method and no POLICY, runs a method of the paper on a composite task with the recipe's\n"
    "(by default the shipped) policies, the skill or transition in control written on each\n"
    "frame and, per frame, in FILE_control.csv (or DIR/control.csv). The video is encoded by\n"
    "ffmpeg when it is on PATH; otherwise, or with --frames, PNG frames are written instead\n"
    "(to FILE_frames/ or DIR).",
    {},
    {{"task", "NAME", "task to run (default: the recipe's task; required for a policy)"},
     {"method", "M", "composite-task method (single, without-tp, tp, lee, tp+q)"},
     {"recipe", "FILE", "with --method: composite recipe (default experiments/TASK.yaml)"},
     {"out", "FILE.mp4", "video to write"},
     {"frames", "DIR", "write PNG frames to DIR instead of a video"},
     {"seed", "S", "episode seed (default 0)"},
     {"steps", "N", "stop after N control steps (default: the episode's time limit)"},
     {"width", "W", "frame width in pixels (default 640)"},
     {"height", "H", "frame height in pixels (default 480)"},
     {"fps", "F", "frames per second of simulated time (default 30)"},
     {"camera", "NAME", "model camera to use, or 'free' (default: 'track' if the model has it)"},
     {"set", "key=value", "override a task setting, e.g. --set env.push_prob=0 (repeatable)", true}},
    1};

std::string egl_error(const std::string& what) {
  char code[16];
  std::snprintf(code, sizeof(code), "0x%04x", eglGetError());
  return "segue render: " + what + " (EGL error " + code + ")";
}

// A desktop-OpenGL context, current on this thread, with no window or pbuffer behind it:
// MuJoCo renders into its own framebuffer object, so no default framebuffer is needed.
class EglContext {
 public:
  EglContext() {
    display_ = surfaceless_display();
    if (!eglInitialize(display_, nullptr, nullptr))
      throw Error(egl_error("cannot initialise the EGL display (are libegl-mesa0 and libgl1-mesa-dri installed?)"));
    const char* ext = eglQueryString(display_, EGL_EXTENSIONS);
    if (!ext || !std::strstr(ext, "EGL_KHR_surfaceless_context"))
      throw Error("segue render: the EGL display lacks EGL_KHR_surfaceless_context");
    const EGLint attribs[] = {EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT,
                              EGL_RED_SIZE, 8, EGL_GREEN_SIZE, 8, EGL_BLUE_SIZE, 8, EGL_ALPHA_SIZE, 8,
                              EGL_DEPTH_SIZE, 24, EGL_STENCIL_SIZE, 8, EGL_NONE};
    EGLConfig config;
    EGLint n = 0;
    if (!eglChooseConfig(display_, attribs, &config, 1, &n) || n < 1)
      throw Error(egl_error("no EGL config with desktop OpenGL and 8-bit RGBA"));
    // MuJoCo 2.2 draws with the fixed-function pipeline: desktop GL (compatibility profile), not GLES.
    if (!eglBindAPI(EGL_OPENGL_API)) throw Error(egl_error("EGL cannot bind the desktop OpenGL API"));
    context_ = eglCreateContext(display_, config, EGL_NO_CONTEXT, nullptr);
    if (context_ == EGL_NO_CONTEXT) throw Error(egl_error("cannot create an OpenGL context"));
    if (!eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_))
      throw Error(egl_error("cannot make the OpenGL context current"));
  }
  ~EglContext() {
    eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    eglDestroyContext(display_, context_);
    eglTerminate(display_);
  }
  EglContext(const EglContext&) = delete;
  EglContext& operator=(const EglContext&) = delete;

 private:
  static EGLDisplay surfaceless_display() {
    // Ask for Mesa's surfaceless platform by name when the client library offers it.
    const char* client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    auto get_platform_display =
        reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
    if (client && std::strstr(client, "EGL_MESA_platform_surfaceless") && get_platform_display) {
      EGLDisplay d = get_platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
      if (d != EGL_NO_DISPLAY) return d;
    }
    // Otherwise Mesa picks the platform from EGL_PLATFORM (a value the user set wins).
    setenv("EGL_PLATFORM", "surfaceless", 0);
    EGLDisplay d = eglGetDisplay(EGL_DEFAULT_DISPLAY);
    if (d == EGL_NO_DISPLAY) throw Error(egl_error("no EGL display (install libegl-mesa0 and libgl1-mesa-dri)"));
    return d;
  }
  EGLDisplay display_ = EGL_NO_DISPLAY;
  EGLContext context_ = EGL_NO_CONTEXT;
};

// MuJoCo's scene and GPU resources for one model, and the camera that films it.
class Renderer {
 public:
  // Needs a current OpenGL context for its whole life.
  Renderer(mjModel* m, int width, int height, const std::string& camera) : m_(m), width_(width), height_(height) {
    // The offscreen buffer is sized by <visual><global offwidth offheight> (640x480 by
    // default); grow it so any requested frame size fits. Visual settings never touch physics.
    m->vis.global.offwidth = std::max(m->vis.global.offwidth, width);
    m->vis.global.offheight = std::max(m->vis.global.offheight, height);
    mjv_defaultCamera(&cam_);
    mjv_defaultOption(&opt_);
    mjv_defaultScene(&scn_);
    mjr_defaultContext(&con_);
    mjv_makeScene(m, &scn_, 2000);
    mjr_makeContext(m, &con_, mjFONTSCALE_150);
    mjr_setBuffer(mjFB_OFFSCREEN, &con_);
    if (con_.currentBuffer != mjFB_OFFSCREEN || con_.offWidth < width || con_.offHeight < height)
      throw Error("segue render: cannot get a " + std::to_string(width) + "x" + std::to_string(height) +
                  " offscreen framebuffer from OpenGL");

    int fixed = mj_name2id(m, mjOBJ_CAMERA, (camera.empty() ? "track" : camera).c_str());
    if (!camera.empty() && camera != "free" && fixed < 0)
      throw Error("segue render: the model has no camera named '" + camera + "'");
    if (fixed >= 0 && camera != "free") {
      cam_.type = mjCAMERA_FIXED;
      cam_.fixedcamid = fixed;
    } else {  // follow the root body from the side, looking along +y at the x-z plane
      cam_.type = mjCAMERA_TRACKING;
      cam_.trackbodyid = 1;
      cam_.distance = 4;
      cam_.elevation = -10;
      cam_.azimuth = 90;
    }
    rows_.resize(size_t(3) * width * height);
  }
  ~Renderer() {
    mjr_freeContext(&con_);
    mjv_freeScene(&scn_);
  }
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  // Draws the current state into `rgb` (width*height*3 bytes, top row first), `label` in
  // its top-left corner.
  void draw(mjData* d, std::vector<unsigned char>& rgb, const std::string& label = "") {
    mjrRect viewport{0, 0, width_, height_};
    mjv_updateScene(m_, d, &opt_, nullptr, &cam_, mjCAT_ALL, &scn_);
    mjr_render(viewport, &scn_, &con_);
    if (!label.empty()) mjr_overlay(mjFONT_BIG, mjGRID_TOPLEFT, viewport, label.c_str(), nullptr, &con_);
    mjr_readPixels(rows_.data(), nullptr, viewport, &con_);
    // OpenGL returns the bottom row first; images and video want the top row first.
    const size_t stride = size_t(3) * width_;
    rgb.resize(rows_.size());
    for (int y = 0; y < height_; ++y)
      std::memcpy(&rgb[y * stride], &rows_[(height_ - 1 - y) * stride], stride);
  }

 private:
  mjModel* m_;
  int width_, height_;
  mjvCamera cam_;
  mjvOption opt_;
  mjvScene scn_;
  mjrContext con_;
  std::vector<unsigned char> rows_;
};

// ---- PNG: stored (uncompressed) deflate blocks keep the writer tiny and dependency-free.

uint32_t crc32(const unsigned char* p, size_t n, uint32_t c = 0) {
  static uint32_t table[256] = {0};
  if (!table[1])
    for (uint32_t i = 0; i < 256; ++i) {
      uint32_t k = i;
      for (int b = 0; b < 8; ++b) k = k & 1 ? 0xedb88320u ^ (k >> 1) : k >> 1;
      table[i] = k;
    }
  c = ~c;
  for (size_t i = 0; i < n; ++i) c = table[(c ^ p[i]) & 0xff] ^ (c >> 8);
  return ~c;
}

void put32(std::string& s, uint32_t v) {
  for (int shift = 24; shift >= 0; shift -= 8) s += char((v >> shift) & 0xff);
}

void write_png(const fs::path& path, const std::vector<unsigned char>& rgb, int width, int height) {
  // Scanlines, each led by filter type 0 (none).
  std::string raw;
  const size_t stride = size_t(3) * width;
  for (int y = 0; y < height; ++y) {
    raw += '\0';
    raw.append(reinterpret_cast<const char*>(&rgb[y * stride]), stride);
  }
  // zlib stream: header, stored blocks of at most 65535 bytes, Adler-32 of the data.
  std::string z = "\x78\x01";
  for (size_t at = 0; at < raw.size(); at += 65535) {
    uint16_t len = uint16_t(std::min<size_t>(65535, raw.size() - at));
    z += char(at + len == raw.size());
    z += char(len & 0xff), z += char(len >> 8), z += char(~len & 0xff), z += char((~len >> 8) & 0xff);
    z.append(raw, at, len);
  }
  uint32_t a = 1, b = 0;
  for (unsigned char c : raw) a = (a + c) % 65521, b = (b + a) % 65521;
  put32(z, (b << 16) | a);

  std::string png = "\x89PNG\r\n\x1a\n";
  auto chunk = [&](const char* type, const std::string& data) {
    put32(png, uint32_t(data.size()));
    std::string body = type + data;
    png += body;
    put32(png, crc32(reinterpret_cast<const unsigned char*>(body.data()), body.size()));
  };
  std::string ihdr;
  put32(ihdr, width), put32(ihdr, height);
  ihdr += std::string("\x08\x02\x00\x00\x00", 5);  // 8-bit RGB, deflate, no filter, no interlace
  chunk("IHDR", ihdr);
  chunk("IDAT", z);
  chunk("IEND", "");
  std::ofstream f(path, std::ios::binary);
  if (!(f << png)) throw Error("segue render: cannot write " + path.string());
}

// ---- Video: raw RGB frames piped into ffmpeg's H.264 encoder.

bool on_path(const std::string& exe) {
  const char* path = std::getenv("PATH");
  std::string dirs = path ? path : "";
  for (size_t at = 0; at <= dirs.size();) {
    size_t end = std::min(dirs.find(':', at), dirs.size());
    std::string dir = dirs.substr(at, end - at);
    if (!dir.empty() && access((dir + "/" + exe).c_str(), X_OK) == 0) return true;
    at = end + 1;
  }
  return false;
}

std::string shell_quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

class FfmpegPipe {
 public:
  FfmpegPipe(const std::string& file, int width, int height, int fps) : file_(file) {
    // A dying ffmpeg must surface as a failed write below, not kill us with SIGPIPE.
    std::signal(SIGPIPE, SIG_IGN);
    std::string cmd = "ffmpeg -y -loglevel error -f rawvideo -pix_fmt rgb24 -s " + std::to_string(width) + "x" +
                      std::to_string(height) + " -r " + std::to_string(fps) +
                      " -i - -pix_fmt yuv420p -vcodec libx264 " + shell_quote(file);
    pipe_ = popen(cmd.c_str(), "w");
    if (!pipe_) throw Error("segue render: cannot start ffmpeg");
  }
  ~FfmpegPipe() {
    if (pipe_) pclose(pipe_);
  }
  FfmpegPipe(const FfmpegPipe&) = delete;
  FfmpegPipe& operator=(const FfmpegPipe&) = delete;

  void write(const std::vector<unsigned char>& rgb) {
    if (std::fwrite(rgb.data(), 1, rgb.size(), pipe_) != rgb.size())
      throw Error("segue render: ffmpeg stopped reading frames while writing " + file_);
  }
  void close() {
    int status = pclose(pipe_);
    pipe_ = nullptr;
    if (status == -1 || !WIFEXITED(status) || WEXITSTATUS(status) != 0)
      throw Error("segue render: ffmpeg failed to write " + file_);
  }

 private:
  std::string file_;
  FILE* pipe_ = nullptr;
};

}  // namespace

int render_main(int argc, char** argv) {
  Args args(kRender, argc, argv);
  if (args.help()) return print_help(kRender);
  if (!args.has("out") && !args.has("frames"))
    throw Error("segue render: --out FILE.mp4 or --frames DIR is required (see segue render --help)");
  if (args.has("task")) require_known_task(args.get("task", ""));
  const int seed = args.get_int("seed", 0, Range::non_negative()),
            width = args.get_int("width", 640, Range::closed(16, 8192)),
            height = args.get_int("height", 480, Range::closed(16, 8192)),
            fps = args.get_int("fps", 30, Range::closed(1, 1000));

  // The task's environment and what acts in it: a method on a composite task, or a policy
  // from a recipe's run directory or a file.
  std::string task;
  std::function<std::unique_ptr<Env>()> make;
  std::unique_ptr<Controller> controller;
  std::string policy_path;    // without --method: the policy, loaded once the env is made
  CompositeRecipe composite;  // with --method: the controllers refer to it
  const bool by_method = args.has("method");
  if (by_method) {
    if (args.positional_count() > 0) throw Error("segue render: give a POLICY or --method, not both");
    if (!args.has("task")) throw Error("segue render: --method needs --task NAME (a composite task)");
    task = args.get("task", "");
    composite = method_recipe("render", args, task, args.all("set"));
    make = composite.make_env;
    controller = method_controllers(composite, args.get("method", ""))();
  } else if (args.positional_count() == 0) {
    throw Error("segue render: give a POLICY (or a recipe), or --method for a composite task");
  } else if (args.has("recipe")) {
    throw Error("segue render: --recipe goes with --method");
  } else {
    const std::string source = args.positional(0);
    policy_path = source;
    if (fs::path(source).extension() == ".yaml") {
      Recipe recipe = Recipe::load(source, args.all("set"));
      SkillRecipe s = SkillRecipe::read(recipe, "runs/" + fs::path(source).stem().string());
      task = args.get("task", s.task);
      make = task == s.task ? s.make_env : task_factory(task, recipe.root().sub("env"));
      recipe.reject_unknown();
      policy_path = (fs::path(s.run_dir) / "checkpoint.pt").string();
      if (!fs::exists(policy_path))
        throw Error("segue render: " + source + ": no checkpoint at " + policy_path + " (train it first)");
    } else {
      if (!args.has("task")) throw Error("segue render: --task NAME is required (see segue render --help)");
      task = args.get("task", "");
      Recipe settings = Recipe::parse("{}", "--set", args.all("set"));
      make = task_factory(task, settings.root().sub("env"));
      settings.reject_unknown();
    }
  }
  std::unique_ptr<Env> env = make();
  auto* mj = dynamic_cast<MujocoEnv*>(env.get());
  if (!mj) throw Error("segue render: task '" + task + "' is not a MuJoCo environment");
  const EnvSpec& spec = env->spec();
  set_torch_threads(1);
  if (!by_method) {
    Policy policy = Policy::load(policy_path);
    policy.check_fits(spec, policy_path);
    controller = std::make_unique<PolicyController>(policy);
  }
  const int steps = args.get_int("steps", spec.max_episode_steps, Range::positive());

  // Where frames go: ffmpeg when asked for a video and available, else PNG files.
  std::string out = args.get("out", "");
  const fs::path out_folder = fs::path(out).parent_path();
  if (!out_folder.empty() && !fs::is_directory(out_folder))
    throw Error("segue render: --out " + out + ": no folder '" + out_folder.string() + "'");
  fs::path frames_dir = args.get("frames", "");
  const bool video = frames_dir.empty() && on_path("ffmpeg");
  if (frames_dir.empty() && !video) {
    frames_dir = fs::path(out).replace_extension().string() + "_frames";
    std::fprintf(stderr, "segue render: ffmpeg is not on PATH; writing PNG frames to %s\n", frames_dir.c_str());
  }
  if (video && (width % 2 || height % 2)) throw Error("segue render: H.264 video needs an even --width and --height");
  if (!video) fs::create_directories(frames_dir);

  install_mujoco_handlers();  // a failing mjr_ call is an error line, not a prompt
  EglContext gl;  // must outlive the renderer, which frees GL resources
  // MujocoEnv hands out its model as const, but each env owns a private copy of it;
  // the renderer only raises that copy's offscreen buffer size (a visual setting).
  Renderer renderer(const_cast<mjModel*>(mj->model()), width, height, args.get("camera", ""));
  std::unique_ptr<FfmpegPipe> pipe;
  if (video) pipe = std::make_unique<FfmpegPipe>(out, width, height, fps);

  std::vector<float> obs(spec.obs_dim), action(spec.act_dim);
  std::vector<unsigned char> rgb;
  int frames = 0;
  double next_frame = 0.0;  // simulated time of the next frame, so the video plays in real time
  // With --method: who is in control at each frame (frame, step, in_control).
  std::string control = "frame,step,in_control\n";
  auto capture = [&](int step) {
    if (step * mj->control_dt() + 1e-9 < next_frame) return;
    const std::string label = by_method ? controller->in_control() : "";
    renderer.draw(mj->mutable_data(), rgb, label);
    if (by_method) control += std::to_string(frames) + "," + std::to_string(step) + "," + label + "\n";
    if (pipe) {
      pipe->write(rgb);
    } else {
      char name[32];
      std::snprintf(name, sizeof(name), "frame_%05d.png", frames);
      write_png(frames_dir / name, rgb, width, height);
    }
    ++frames;
    next_frame += 1.0 / fps;
  };

  env->reset(uint64_t(seed), obs.data());
  controller->reset(*env, obs.data(), uint64_t(seed));
  // The first frame shows the state before any action: who will act on it is known once
  // the controller has chosen, so each frame is labelled by the action taken from it.
  double ret = 0.0, successes = 0.0;
  bool success = false;
  controller->act(*env, obs.data(), action.data());
  capture(0);
  for (int t = 1; t <= steps; ++t) {
    StepResult r = env->step(action.data(), obs.data());
    ret += r.reward;
    success = r.info.success;
    successes = r.info.success_count;
    if (r.done() || t == steps) {
      capture(t);
      break;
    }
    controller->act(*env, obs.data(), action.data());
    capture(t);
  }
  if (pipe) pipe->close();
  if (by_method) {
    const fs::path file = video ? fs::path(fs::path(out).replace_extension().string() + "_control.csv")
                                : frames_dir / "control.csv";
    write_file_atomic(file.string(), control);
  }
  if (by_method)
    std::printf("wrote %s (%d frames, episode return %.2f, success count %g)\n",
                video ? out.c_str() : frames_dir.c_str(), frames, ret, successes);
  else
    std::printf("wrote %s (%d frames, episode return %.2f, success %s)\n",
                video ? out.c_str() : frames_dir.c_str(), frames, ret, success ? "yes" : "no");
  return 0;
}

}  // namespace segue::cli
