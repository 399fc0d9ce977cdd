#include "render/gl_context.h"

#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GL/osmesa.h>
#include <dlfcn.h>

#include <cstdlib>
#include <mutex>
#include <optional>
#include <vector>

namespace recruit::render {
namespace {

// MuJoCo binds its GL loader to one platform per process (see the header).
std::mutex g_backend_mutex;
std::optional<GlBackend> g_backend;

Status ClaimBackend(GlBackend backend) {
  std::lock_guard<std::mutex> lock(g_backend_mutex);
  if (g_backend && *g_backend != backend) {
    return Error{std::string("GL back end '") + GlBackendName(backend) +
                 "' requested, but this process already rendered with '" +
                 GlBackendName(*g_backend) +
                 "': MuJoCo binds its GL loader once per process, use one back end"};
  }
  g_backend = backend;
  return Status::Ok();
}

class OsMesaContext final : public GlContext {
 public:
  OsMesaContext() : GlContext(GlBackend::kOsMesa) {}
  ~OsMesaContext() override {
    if (ctx_) OSMesaDestroyContext(ctx_);
  }

  Status Init(int width, int height) {
    // RGBA colour, 24-bit depth, 8-bit stencil, no accumulation buffer.
    ctx_ = OSMesaCreateContextExt(OSMESA_RGBA, 24, 8, 0, nullptr);
    if (!ctx_) return Error{"OSMesaCreateContextExt failed: is libOSMesa (libosmesa6) installed?"};
    width_ = width;
    height_ = height;
    buffer_.assign(static_cast<size_t>(width) * height * 4, 0);
    return MakeCurrent();
  }

  Status MakeCurrent() override {
    if (!OSMesaMakeCurrent(ctx_, buffer_.data(), GL_UNSIGNED_BYTE, width_, height_)) {
      return Error{"OSMesaMakeCurrent failed for a " + std::to_string(width_) + "x" +
                   std::to_string(height_) + " buffer"};
    }
    return Status::Ok();
  }

  void* GetProcAddress(const char* name) const override {
    return reinterpret_cast<void*>(OSMesaGetProcAddress(name));
  }

 private:
  OSMesaContext ctx_ = nullptr;
  int width_ = 0, height_ = 0;
  std::vector<unsigned char> buffer_;
};

// EGL entry points, resolved from libEGL.so.1 opened at run time (libEGL is never linked).
struct EglApi {
  void* lib = nullptr;
  PFNEGLGETPROCADDRESSPROC GetProcAddress = nullptr;
  PFNEGLGETDISPLAYPROC GetDisplay = nullptr;
  PFNEGLINITIALIZEPROC Initialize = nullptr;
  PFNEGLTERMINATEPROC Terminate = nullptr;
  PFNEGLCHOOSECONFIGPROC ChooseConfig = nullptr;
  PFNEGLBINDAPIPROC BindAPI = nullptr;
  PFNEGLCREATECONTEXTPROC CreateContext = nullptr;
  PFNEGLDESTROYCONTEXTPROC DestroyContext = nullptr;
  PFNEGLMAKECURRENTPROC MakeCurrent = nullptr;
  PFNEGLGETERRORPROC GetError = nullptr;
  PFNEGLQUERYDEVICESEXTPROC QueryDevices = nullptr;
  PFNEGLGETPLATFORMDISPLAYEXTPROC GetPlatformDisplay = nullptr;
};

Result<EglApi*> LoadEgl() {
  static EglApi api;
  static std::string error;
  static ErrorCode code = ErrorCode::kBadInput;
  static std::once_flag once;
  std::call_once(once, [] {
    // RTLD_GLOBAL: MuJoCo's loader looks up eglGetProcAddress among the global symbols.
    api.lib = dlopen("libEGL.so.1", RTLD_NOW | RTLD_GLOBAL);
    if (!api.lib) {
      error = std::string("GL back end 'egl': cannot open libEGL.so.1 (") + dlerror() +
              "); install a GPU driver's EGL (or libegl1) or use --gl osmesa";
      code = ErrorCode::kIo;
      return;
    }
    auto sym = [](const char* name) { return dlsym(api.lib, name); };
    api.GetProcAddress = reinterpret_cast<PFNEGLGETPROCADDRESSPROC>(sym("eglGetProcAddress"));
    api.GetDisplay = reinterpret_cast<PFNEGLGETDISPLAYPROC>(sym("eglGetDisplay"));
    api.Initialize = reinterpret_cast<PFNEGLINITIALIZEPROC>(sym("eglInitialize"));
    api.Terminate = reinterpret_cast<PFNEGLTERMINATEPROC>(sym("eglTerminate"));
    api.ChooseConfig = reinterpret_cast<PFNEGLCHOOSECONFIGPROC>(sym("eglChooseConfig"));
    api.BindAPI = reinterpret_cast<PFNEGLBINDAPIPROC>(sym("eglBindAPI"));
    api.CreateContext = reinterpret_cast<PFNEGLCREATECONTEXTPROC>(sym("eglCreateContext"));
    api.DestroyContext = reinterpret_cast<PFNEGLDESTROYCONTEXTPROC>(sym("eglDestroyContext"));
    api.MakeCurrent = reinterpret_cast<PFNEGLMAKECURRENTPROC>(sym("eglMakeCurrent"));
    api.GetError = reinterpret_cast<PFNEGLGETERRORPROC>(sym("eglGetError"));
    if (!api.GetProcAddress || !api.GetDisplay || !api.Initialize || !api.ChooseConfig ||
        !api.BindAPI || !api.CreateContext || !api.MakeCurrent || !api.GetError) {
      error = "GL back end 'egl': libEGL.so.1 lacks core EGL 1.4 entry points";
      return;
    }
    api.QueryDevices =
        reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(api.GetProcAddress("eglQueryDevicesEXT"));
    api.GetPlatformDisplay = reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(
        api.GetProcAddress("eglGetPlatformDisplayEXT"));
  });
  if (!error.empty()) return Error{error, code};
  return &api;
}

class EglContext final : public GlContext {
 public:
  EglContext() : GlContext(GlBackend::kEgl) {}
  ~EglContext() override {
    if (ctx_ != EGL_NO_CONTEXT) {
      api_->MakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
      api_->DestroyContext(display_, ctx_);
    }
  }

  Status Init() {
    auto api = LoadEgl();
    if (!api.ok()) return Error{api.error(), api.code()};
    api_ = *api;
    display_ = EGL_NO_DISPLAY;
    // Prefer the first EGL device (a GPU, or Mesa's software device): no window system needed.
    if (api_->QueryDevices && api_->GetPlatformDisplay) {
      EGLDeviceEXT devices[8];
      EGLint count = 0;
      if (api_->QueryDevices(8, devices, &count) && count > 0) {
        for (EGLint i = 0; i < count && display_ == EGL_NO_DISPLAY; ++i) {
          EGLDisplay d = api_->GetPlatformDisplay(EGL_PLATFORM_DEVICE_EXT, devices[i], nullptr);
          EGLint major = 0, minor = 0;
          if (d != EGL_NO_DISPLAY && api_->Initialize(d, &major, &minor)) display_ = d;
        }
      }
    }
    if (display_ == EGL_NO_DISPLAY) {
      EGLDisplay d = api_->GetDisplay(EGL_DEFAULT_DISPLAY);
      EGLint major = 0, minor = 0;
      if (d == EGL_NO_DISPLAY || !api_->Initialize(d, &major, &minor)) {
        return Error{"GL back end 'egl': no EGL display could be initialised (EGL error 0x" +
                     Hex(api_->GetError()) + "); use --gl osmesa on machines without a GPU"};
      }
      display_ = d;
    }
    const EGLint config_attribs[] = {EGL_RED_SIZE,
                                     8,
                                     EGL_GREEN_SIZE,
                                     8,
                                     EGL_BLUE_SIZE,
                                     8,
                                     EGL_ALPHA_SIZE,
                                     8,
                                     EGL_DEPTH_SIZE,
                                     24,
                                     EGL_STENCIL_SIZE,
                                     8,
                                     EGL_COLOR_BUFFER_TYPE,
                                     EGL_RGB_BUFFER,
                                     EGL_SURFACE_TYPE,
                                     EGL_PBUFFER_BIT,
                                     EGL_RENDERABLE_TYPE,
                                     EGL_OPENGL_BIT,
                                     EGL_NONE};
    EGLConfig config;
    EGLint num_configs = 0;
    if (!api_->ChooseConfig(display_, config_attribs, &config, 1, &num_configs) ||
        num_configs < 1) {
      return Error{"GL back end 'egl': no RGBA8/depth24/stencil8 desktop-GL config (EGL error 0x" +
                   Hex(api_->GetError()) + ")"};
    }
    if (!api_->BindAPI(EGL_OPENGL_API)) {
      return Error{"GL back end 'egl': eglBindAPI(EGL_OPENGL_API) failed"};
    }
    ctx_ = api_->CreateContext(display_, config, EGL_NO_CONTEXT, nullptr);
    if (ctx_ == EGL_NO_CONTEXT) {
      return Error{"GL back end 'egl': eglCreateContext failed (EGL error 0x" +
                   Hex(api_->GetError()) + ")"};
    }
    return MakeCurrent();
  }

  Status MakeCurrent() override {
    // Surfaceless: MuJoCo draws into its own framebuffer object.
    if (!api_->MakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, ctx_)) {
      return Error{"GL back end 'egl': eglMakeCurrent without a surface failed (EGL error 0x" +
                   Hex(api_->GetError()) + "; needs EGL_KHR_surfaceless_context)"};
    }
    return Status::Ok();
  }

  void* GetProcAddress(const char* name) const override {
    return reinterpret_cast<void*>(api_->GetProcAddress(name));
  }

 private:
  static std::string Hex(EGLint v) {
    char buf[16];
    std::snprintf(buf, sizeof(buf), "%04X", static_cast<unsigned>(v));
    return buf;
  }

  EglApi* api_ = nullptr;
  EGLDisplay display_ = EGL_NO_DISPLAY;
  EGLContext ctx_ = EGL_NO_CONTEXT;
};

}  // namespace

Result<GlBackend> ParseGlBackend(const std::string& name) {
  if (name == "osmesa") return GlBackend::kOsMesa;
  if (name == "egl") return GlBackend::kEgl;
  return Error{"unknown GL back end '" + name +
               "': allowed are 'osmesa' (software, default) "
               "and 'egl' (GPU driver)"};
}

const char* GlBackendName(GlBackend backend) {
  return backend == GlBackend::kEgl ? "egl" : "osmesa";
}

Result<GlBackend> GlBackendFromEnvironment() {
  for (const char* var : {"RECRUIT_GL", "MUJOCO_GL"}) {
    const char* value = std::getenv(var);
    if (value && *value) {
      auto b = ParseGlBackend(value);
      if (!b.ok())
        return Error{std::string("environment variable ") + var + ": " + b.error(), b.code()};
      return b;
    }
  }
  return GlBackend::kOsMesa;
}

Result<std::unique_ptr<GlContext>> GlContext::Create(GlBackend backend, int width, int height) {
  if (width <= 0 || height <= 0) {
    return Error{"GL context size must be positive, got " + std::to_string(width) + "x" +
                 std::to_string(height)};
  }
  if (Status s = ClaimBackend(backend); !s.ok()) return Error{s.error(), s.code()};
  if (backend == GlBackend::kEgl) {
    auto ctx = std::make_unique<EglContext>();
    if (Status s = ctx->Init(); !s.ok()) return Error{s.error(), s.code()};
    return std::unique_ptr<GlContext>(std::move(ctx));
  }
  auto ctx = std::make_unique<OsMesaContext>();
  if (Status s = ctx->Init(width, height); !s.ok()) return Error{s.error(), s.code()};
  return std::unique_ptr<GlContext>(std::move(ctx));
}

std::string GlContext::Description() const {
  using GetStringFn = const unsigned char* (*)(unsigned int);
  auto get_string = reinterpret_cast<GetStringFn>(GetProcAddress("glGetString"));
  if (!get_string) return GlBackendName(backend_);
  auto str = [&](unsigned int e) {
    const unsigned char* s = get_string(e);
    return s ? std::string(reinterpret_cast<const char*>(s)) : std::string("?");
  };
  return std::string(GlBackendName(backend_)) + ": " + str(GL_RENDERER) + ", OpenGL " +
         str(GL_VERSION);
}

int GlContext::MaxRenderbufferSize() const {
  using GetIntegervFn = void (*)(unsigned int, int*);
  auto get_integerv = reinterpret_cast<GetIntegervFn>(GetProcAddress("glGetIntegerv"));
  if (!get_integerv) return 0;
  int size = 0;
  get_integerv(0x84E8 /* GL_MAX_RENDERBUFFER_SIZE */, &size);
  return size;
}

}  // namespace recruit::render
