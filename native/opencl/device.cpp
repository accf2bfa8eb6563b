#include "opencl/device.h"

#include <chrono>
#include <cstdlib>
#include <cstring>
#include <map>
#include <memory>
#include <mutex>
#include <vector>

namespace toyrt::opencl {

void check(cl_int status, const char* what) {
  if (status != CL_SUCCESS)
    throw OpenClError(std::string("OpenCL: ") + what + " failed (error " + std::to_string(status) + ")");
}

namespace {

std::string info(cl_platform_id p, cl_platform_info key) {
  size_t size = 0;
  clGetPlatformInfo(p, key, 0, nullptr, &size);
  std::string s(size, '\0');
  clGetPlatformInfo(p, key, size, s.data(), nullptr);
  return s.c_str();
}

std::string info(cl_device_id d, cl_device_info key) {
  size_t size = 0;
  clGetDeviceInfo(d, key, 0, nullptr, &size);
  std::string s(size, '\0');
  clGetDeviceInfo(d, key, size, s.data(), nullptr);
  return s.c_str();
}

Device open_device() {
  const char* env = std::getenv("TOYRT_OPENCL");
  if (env && std::strcmp(env, "off") == 0) throw OpenClError("OpenCL is switched off (TOYRT_OPENCL=off)");
  cl_uint platform_count = 0;
  if (clGetPlatformIDs(0, nullptr, &platform_count) != CL_SUCCESS || platform_count == 0)
    throw OpenClError("no OpenCL platform found (install an OpenCL driver, e.g. Debian's pocl-opencl-icd)");
  std::vector<cl_platform_id> platforms(platform_count);
  check(clGetPlatformIDs(platform_count, platforms.data(), nullptr), "clGetPlatformIDs");
  Device dev;
  cl_platform_id chosen = nullptr;
  for (cl_device_type type : {cl_device_type(CL_DEVICE_TYPE_GPU), cl_device_type(CL_DEVICE_TYPE_ALL)}) {
    for (cl_platform_id p : platforms) {
      cl_uint n = 0;
      if (clGetDeviceIDs(p, type, 1, &dev.device, &n) == CL_SUCCESS && n > 0) {
        chosen = p;
        break;
      }
    }
    if (chosen) break;
  }
  if (!chosen) throw OpenClError("no OpenCL device found on " + std::to_string(platform_count) + " platform(s)");
  dev.name = info(chosen, CL_PLATFORM_NAME) + ": " + info(dev.device, CL_DEVICE_NAME);
  cl_device_type type = 0;
  check(clGetDeviceInfo(dev.device, CL_DEVICE_TYPE, sizeof type, &type, nullptr), "clGetDeviceInfo");
  dev.gpu = (type & CL_DEVICE_TYPE_GPU) != 0;
  cl_int status = CL_SUCCESS;
  dev.context = clCreateContext(nullptr, 1, &dev.device, nullptr, nullptr, &status);
  check(status, "clCreateContext");
  dev.queue = clCreateCommandQueue(dev.context, dev.device, 0, &status);
  check(status, "clCreateCommandQueue");
  return dev;
}

std::mutex g_mutex;
std::unique_ptr<Device> g_device;
std::string g_device_error;
std::map<std::string, Program> g_programs;

}  // namespace

const Device& device() {
  std::lock_guard lock(g_mutex);
  if (g_device) return *g_device;
  if (!g_device_error.empty()) throw OpenClError(g_device_error);  // fail fast after the first try
  try {
    g_device = std::make_unique<Device>(open_device());
  } catch (const OpenClError& e) {
    g_device_error = e.what();
    throw;
  }
  return *g_device;
}

cl_program compile(const std::string& source, const std::string& options, double* compile_ms) {
  const Device& dev = device();
  const auto start = std::chrono::steady_clock::now();
  const char* text = source.c_str();
  const size_t length = source.size();
  cl_int status = CL_SUCCESS;
  cl_program p = clCreateProgramWithSource(dev.context, 1, &text, &length, &status);
  check(status, "clCreateProgramWithSource");
  if (clBuildProgram(p, 1, &dev.device, options.c_str(), nullptr, nullptr) != CL_SUCCESS) {
    size_t size = 0;
    clGetProgramBuildInfo(p, dev.device, CL_PROGRAM_BUILD_LOG, 0, nullptr, &size);
    std::string log(size, '\0');
    clGetProgramBuildInfo(p, dev.device, CL_PROGRAM_BUILD_LOG, size, log.data(), nullptr);
    clReleaseProgram(p);
    throw OpenClError("OpenCL: kernel build failed on " + dev.name + ":\n" + log.c_str());
  }
  if (compile_ms)
    *compile_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return p;
}

const Program& program(const std::string& key, const std::string& source, const std::string& options) {
  device();  // opens it, or throws, outside our lock
  {
    std::lock_guard lock(g_mutex);
    auto it = g_programs.find(key);
    if (it != g_programs.end()) return it->second;
  }
  Program prog;
  prog.program = compile(source, options, &prog.compile_ms);
  std::lock_guard lock(g_mutex);
  auto [it, inserted] = g_programs.emplace(key, prog);
  if (!inserted) clReleaseProgram(prog.program);  // another thread compiled it meanwhile
  return it->second;
}

Kernel::Kernel(cl_program program, const char* name) : name_(name) {
  cl_int status = CL_SUCCESS;
  kernel_ = clCreateKernel(program, name, &status);
  check(status, name);
}

Kernel::~Kernel() {
  if (kernel_) clReleaseKernel(kernel_);
}

void Kernel::run(size_t global) const {
  if (global == 0) return;
  check(clEnqueueNDRangeKernel(device().queue, kernel_, 1, nullptr, &global, nullptr, 0, nullptr, nullptr), name_);
}

Buffer::Buffer(size_t bytes, cl_mem_flags flags, const void* host) {
  cl_int status = CL_SUCCESS;
  if (host) flags |= CL_MEM_USE_HOST_PTR;
  mem_ = clCreateBuffer(device().context, flags, bytes == 0 ? 4 : bytes, const_cast<void*>(host), &status);
  check(status, "clCreateBuffer");
}

Buffer::~Buffer() {
  if (mem_) clReleaseMemObject(mem_);
}

void Buffer::write(const void* data, size_t bytes) const {
  check(clEnqueueWriteBuffer(device().queue, mem_, CL_TRUE, 0, bytes, data, 0, nullptr, nullptr),
        "clEnqueueWriteBuffer");
}

void Buffer::read(void* data, size_t bytes) const {
  check(clEnqueueReadBuffer(device().queue, mem_, CL_TRUE, 0, bytes, data, 0, nullptr, nullptr), "clEnqueueReadBuffer");
}

void Buffer::sync_to_host(size_t bytes) const {
  cl_int status = CL_SUCCESS;
  void* p = clEnqueueMapBuffer(device().queue, mem_, CL_TRUE, CL_MAP_READ, 0, bytes, 0, nullptr, nullptr, &status);
  check(status, "clEnqueueMapBuffer");
  check(clEnqueueUnmapMemObject(device().queue, mem_, p, 0, nullptr, nullptr), "clEnqueueUnmapMemObject");
}

const void* Buffer::map_read(size_t bytes) const {
  cl_int status = CL_SUCCESS;
  void* p = clEnqueueMapBuffer(device().queue, mem_, CL_TRUE, CL_MAP_READ, 0, bytes, 0, nullptr, nullptr, &status);
  check(status, "clEnqueueMapBuffer");
  return p;
}

void Buffer::unmap(const void* mapped) const {
  check(clEnqueueUnmapMemObject(device().queue, mem_, const_cast<void*>(mapped), 0, nullptr, nullptr),
        "clEnqueueUnmapMemObject");
}

void Buffer::fill_zero(size_t bytes) const {
  const cl_int zero = 0;
  check(clEnqueueFillBuffer(device().queue, mem_, &zero, sizeof zero, 0, bytes, 0, nullptr, nullptr),
        "clEnqueueFillBuffer");
}

}  // namespace toyrt::opencl
