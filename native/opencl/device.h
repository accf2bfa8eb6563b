// The process's OpenCL device, set up once: the first GPU of any platform, else the first device
// of any kind (PoCL's CPU device here). Programs are compiled once per process and kept. Every
// failure is reported as an OpenClError with a message that says what failed, never a crash, so
// callers can fall back to a CPU path.
#pragma once

#include <string>

#define CL_TARGET_OPENCL_VERSION 120
#include <CL/cl.h>

#include <stdexcept>

namespace toyrt::opencl {

struct OpenClError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Throws OpenClError naming the call when status is not CL_SUCCESS.
void check(cl_int status, const char* what);

struct Device {
  cl_context context = nullptr;
  cl_command_queue queue = nullptr;
  cl_device_id device = nullptr;
  std::string name;  // platform and device, for reports
  bool gpu = false;  // CL_DEVICE_TYPE_GPU; else a CPU (PoCL's) or an accelerator
};

// The shared device; throws OpenClError if there is none (or TOYRT_OPENCL=off in the environment,
// which lets tests and users force the CPU fallback).
const Device& device();

struct Program {
  cl_program program = nullptr;
  double compile_ms = 0.0;  // of the first (and only) compilation in this process
};

// Compiles `source` with `options` the first time a given `key` is asked for, then returns the
// same program. A build failure throws OpenClError carrying the compiler's log.
const Program& program(const std::string& key, const std::string& source, const std::string& options = "");

// Compiles without caching (for tests of the failure path).
cl_program compile(const std::string& source, const std::string& options, double* compile_ms = nullptr);

// A kernel object from a program, released when it goes out of scope.
class Kernel {
 public:
  Kernel(cl_program program, const char* name);
  ~Kernel();
  Kernel(const Kernel&) = delete;
  Kernel& operator=(const Kernel&) = delete;
  template <class T>
  Kernel& arg(cl_uint index, const T& value) {
    check(clSetKernelArg(kernel_, index, sizeof(T), &value), name_);
    return *this;
  }
  // Enqueues over `global` work-items (a multiple of nothing: kernels bound-check themselves).
  void run(size_t global) const;

 private:
  cl_kernel kernel_ = nullptr;
  const char* name_;
};

// A device buffer of `bytes`, released when it goes out of scope.
class Buffer {
 public:
  // With `host`, the buffer is created over that memory (CL_MEM_USE_HOST_PTR): on a CPU device the
  // kernels then read and write it in place, with no copies; `host` must outlive the buffer.
  Buffer(size_t bytes, cl_mem_flags flags = CL_MEM_READ_WRITE, const void* host = nullptr);
  ~Buffer();
  Buffer(const Buffer&) = delete;
  Buffer& operator=(const Buffer&) = delete;
  cl_mem get() const { return mem_; }
  void write(const void* data, size_t bytes) const;
  void read(void* data, size_t bytes) const;
  void fill_zero(size_t bytes) const;
  // Makes kernel writes to a host-memory buffer visible to the host (a map, no copy on a CPU).
  void sync_to_host(size_t bytes) const;
  // The first `bytes` mapped for reading (no copy on a CPU device); unmap() each pointer once.
  const void* map_read(size_t bytes) const;
  void unmap(const void* mapped) const;

 private:
  cl_mem mem_ = nullptr;
};

}  // namespace toyrt::opencl
