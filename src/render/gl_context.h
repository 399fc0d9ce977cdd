// GlContext: a headless OpenGL context made current on the calling thread, created before
// mjr_makeContext. Two back ends:
//   - OSMesa (default): Mesa's software renderer (llvmpipe), no display and no GPU needed.
//     libOSMesa is linked; libEGL is not, so MuJoCo's GL loader (which looks for
//     eglGetProcAddress first, then OSMesaGetProcAddress, then glXGetProcAddressARB in the
//     process's global symbols) binds to OSMesa.
//   - EGL (opt-in, for machines with a GPU driver): libEGL.so.1 is opened at run time with
//     RTLD_GLOBAL, so the loader finds eglGetProcAddress first, and a surfaceless desktop-GL
//     context is created on the default (or device) display.
// MuJoCo resolves GL entry points once per process, so a process uses one back end: asking for
// the other one afterwards is an error.
#pragma once

#include <memory>
#include <string>

#include "common/result.h"

namespace recruit::render {

enum class GlBackend { kOsMesa, kEgl };

// "osmesa" or "egl" (case-sensitive); the error lists the allowed values.
Result<GlBackend> ParseGlBackend(const std::string& name);
const char* GlBackendName(GlBackend backend);

// The back end named by the environment: RECRUIT_GL, else MUJOCO_GL (the convention of MuJoCo's
// Python bindings), else OSMesa. An unknown value is an error naming the variable.
Result<GlBackend> GlBackendFromEnvironment();

class GlContext {
 public:
  virtual ~GlContext() = default;
  GlContext(const GlContext&) = delete;
  GlContext& operator=(const GlContext&) = delete;

  // Creates a context whose default framebuffer is at least width x height (MuJoCo renders
  // into its own offscreen framebuffer object, so this only has to be valid) and makes it
  // current on this thread.
  static Result<std::unique_ptr<GlContext>> Create(GlBackend backend, int width, int height);

  // Makes the context current on the calling thread again.
  virtual Status MakeCurrent() = 0;
  GlBackend backend() const { return backend_; }
  // GL_RENDERER / GL_VERSION strings, for logs and the benchmark page.
  std::string Description() const;
  // The largest renderbuffer side the driver allows (GL_MAX_RENDERBUFFER_SIZE).
  int MaxRenderbufferSize() const;
  // A GL entry point from this back end's loader (never from a linked libGL).
  virtual void* GetProcAddress(const char* name) const = 0;

 protected:
  explicit GlContext(GlBackend backend) : backend_(backend) {}

 private:
  GlBackend backend_;
};

}  // namespace recruit::render
