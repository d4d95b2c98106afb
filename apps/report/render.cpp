#include "apps/report/render.h"

#include <X11/Xlib.h>
#include <vtkActor.h>
#include <vtkCamera.h>
#include <vtkCellData.h>
#include <vtkDoubleArray.h>
#include <vtkLookupTable.h>
#include <vtkNew.h>
#include <vtkPNGWriter.h>
#include <vtkPolyDataMapper.h>
#include <vtkPolyDataNormals.h>
#include <vtkProperty.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkSMPTools.h>
#include <vtkScalarBarActor.h>
#include <vtkTextProperty.h>
#include <vtkUnsignedCharArray.h>
#include <vtkWindowToImageFilter.h>

#include <poll.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <cstdlib>
#include <string>

#include "mesh/errors.h"
#include "mesh/vtk_convert.h"

namespace mrsnake::reports {

namespace {

// Set once a render outlasted its time: the display or the renderer hangs, and every later
// picture would wait as long again.
std::atomic<bool>& renderer_stalled() {
  static std::atomic<bool> stalled{false};
  return stalled;
}

}  // namespace

bool display_available(std::string* why) {
  if (renderer_stalled()) {
    if (why) *why = "an earlier 3D render did not finish in its time, so later ones are left out";
    return false;
  }
  // Probed once per process: the answer does not change, and repeated connections to a
  // busy Xvfb have been seen to fail.
  static const std::string problem = [] {
    const char* name = std::getenv("DISPLAY");
    if (!name || !*name) return std::string("no DISPLAY is set (run under xvfb-run -a for 3D pictures)");
    Display* display = XOpenDisplay(nullptr);
    if (!display) return std::string("the X display '") + name + "' does not answer";
    XCloseDisplay(display);
    return std::string();
  }();
  if (why) *why = problem;
  return problem.empty();
}

namespace {

std::vector<std::uint8_t> render_in_this_process(const TriMesh& mesh, const RenderOptions& options) {
  vtkNew<vtkRenderer> renderer;
  renderer->SetBackground(1, 1, 1);
  renderer->SetBackground2(0.82, 0.86, 0.92);
  renderer->GradientBackgroundOn();

  auto poly = to_polydata(mesh);
  vtkNew<vtkPolyDataMapper> mapper;
  if (!options.face_scalars.empty()) {
    vtkNew<vtkDoubleArray> values;
    values->SetName("value");
    values->SetNumberOfValues(static_cast<vtkIdType>(options.face_scalars.size()));
    double lo = 1e300, hi = -1e300;
    for (std::size_t i = 0; i < options.face_scalars.size(); ++i) {
      double v = options.face_scalars[i];
      if (options.log_scale) v = std::log10(std::max(v, 1e-300));
      values->SetValue(static_cast<vtkIdType>(i), v);
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
    poly->GetCellData()->SetScalars(values);
    vtkNew<vtkLookupTable> lut;
    lut->SetHueRange(0.667, 0.0);  // blue (low) to red (high)
    lut->SetTableRange(lo, hi > lo ? hi : lo + 1);
    lut->Build();
    mapper->SetLookupTable(lut);
    mapper->SetScalarRange(lo, hi > lo ? hi : lo + 1);
    mapper->SetScalarModeToUseCellData();
    mapper->ScalarVisibilityOn();
    vtkNew<vtkScalarBarActor> bar;
    bar->SetLookupTable(lut);
    bar->SetTitle((options.scalar_title + (options.log_scale ? " (log10)" : "")).c_str());
    bar->SetNumberOfLabels(4);
    bar->SetWidth(0.12);
    bar->GetTitleTextProperty()->SetColor(0.1, 0.1, 0.1);
    bar->GetLabelTextProperty()->SetColor(0.1, 0.1, 0.1);
    renderer->AddActor2D(bar);
  } else {
    mapper->ScalarVisibilityOff();
  }
  mapper->SetInputData(poly);
  vtkNew<vtkActor> actor;
  actor->SetMapper(mapper);
  actor->GetProperty()->SetColor(0.93, 0.72, 0.55);
  actor->GetProperty()->SetSpecular(0.2);
  if (options.wireframe) {
    actor->GetProperty()->EdgeVisibilityOn();
    actor->GetProperty()->SetEdgeColor(0.15, 0.15, 0.2);
    actor->GetProperty()->SetLineWidth(0.6f);
  }
  renderer->AddActor(actor);

  if (options.overlay) {
    vtkNew<vtkPolyDataMapper> overlay_mapper;
    overlay_mapper->SetInputData(to_polydata(*options.overlay));
    overlay_mapper->ScalarVisibilityOff();
    vtkNew<vtkActor> overlay;
    overlay->SetMapper(overlay_mapper);
    overlay->GetProperty()->SetColor(0.2, 0.6, 0.3);
    overlay->GetProperty()->SetOpacity(0.35);
    renderer->AddActor(overlay);
  }

  vtkNew<vtkRenderWindow> window;
  window->SetOffScreenRendering(1);
  window->SetMultiSamples(4);
  window->SetSize(options.width, options.height);
  window->AddRenderer(renderer);
  renderer->ResetCamera();
  renderer->GetActiveCamera()->Azimuth(options.azimuth);
  renderer->GetActiveCamera()->Elevation(options.elevation);
  renderer->GetActiveCamera()->OrthogonalizeViewUp();
  renderer->ResetCamera();
  renderer->GetActiveCamera()->Zoom(1.15);
  window->Render();

  vtkNew<vtkWindowToImageFilter> grab;
  grab->SetInput(window);
  grab->ReadFrontBufferOff();
  grab->Update();
  vtkNew<vtkPNGWriter> writer;
  writer->SetInputConnection(grab->GetOutputPort());
  writer->WriteToMemoryOn();
  writer->Write();
  vtkUnsignedCharArray* result = writer->GetResult();
  return {result->GetPointer(0), result->GetPointer(0) + result->GetNumberOfValues()};
}

// A render running in a forked child, its PNG coming through a pipe.
struct RenderChild {
  pid_t pid = -1;
  int png_fd = -1;
};

RenderChild start_render_child(const TriMesh& mesh, const RenderOptions& options) {
  int fds[2];
  if (pipe(fds) != 0) throw Error(std::string("cannot render: pipe failed: ") + std::strerror(errno));
  std::fflush(stdout);
  std::fflush(stderr);
  const pid_t pid = fork();
  if (pid < 0) {
    close(fds[0]);
    close(fds[1]);
    throw Error(std::string("cannot render: fork failed: ") + std::strerror(errno));
  }
  if (pid > 0) {
    close(fds[1]);
    return {pid, fds[0]};
  }
  close(fds[0]);
  // The child has only this thread. VTK's default parallel backend (TBB) keeps the parent's
  // worker state, and TBB is not safe to use after fork: render on this thread alone.
  vtkSMPTools::SetBackend("Sequential");
  int code = 0;
  try {
    const std::vector<std::uint8_t> png = render_in_this_process(mesh, options);
    for (std::size_t done = 0; done < png.size();) {
      const ssize_t n = write(fds[1], png.data() + done, png.size() - done);
      if (n <= 0) {
        code = 3;
        break;
      }
      done += static_cast<std::size_t>(n);
    }
  } catch (...) {
    code = 2;
  }
  close(fds[1]);
  _exit(code);  // no atexit handlers or static destructors of the parent's state
}

// Reads the child's PNG until the pipe closes. \return false if `max_seconds` passed first.
bool read_png_in_time(int fd, double max_seconds, std::vector<std::uint8_t>* png) {
  using Clock = std::chrono::steady_clock;
  const auto deadline = Clock::now() + std::chrono::duration<double>(std::max(0.0, max_seconds));
  std::uint8_t buffer[65536];
  for (;;) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
    if (left <= 0) return false;
    pollfd waiting{fd, POLLIN, 0};
    const int ready = poll(&waiting, 1, static_cast<int>(std::min<long long>(left, 60'000)));
    if (ready < 0 && errno != EINTR) return false;  // cannot wait on the pipe: stop the child
    if (ready <= 0) continue;
    const ssize_t n = read(fd, buffer, sizeof buffer);
    if (n > 0) {
      png->insert(png->end(), buffer, buffer + n);
    } else if (n == 0 || errno != EINTR) {
      return true;
    }
  }
}

int wait_for_child(pid_t pid) {
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  return status;
}

}  // namespace

std::vector<std::uint8_t> render_mesh_png(const TriMesh& mesh, const RenderOptions& options) {
  std::string why;
  if (!display_available(&why)) throw Error("cannot render: " + why);
  // VTK's X window calls abort() when it cannot get a GL context (an X server that goes
  // away, a visual it does not like), and a render can hang (a stalled display, a lock held
  // at the fork). Render in a child process under a deadline, so that such a failure costs
  // one picture and not the program.
  const RenderChild child = start_render_child(mesh, options);
  std::vector<std::uint8_t> png;
  const bool finished = read_png_in_time(child.png_fd, options.max_seconds, &png);
  close(child.png_fd);
  if (!finished) {
    kill(child.pid, SIGKILL);
    wait_for_child(child.pid);
    renderer_stalled() = true;
    char seconds[32];
    std::snprintf(seconds, sizeof seconds, "%g", options.max_seconds);
    throw Error(std::string("the 3D renderer did not finish within ") + seconds +
                " s and was stopped; later renders are left out");
  }
  const int status = wait_for_child(child.pid);
  if (WIFSIGNALED(status))
    throw Error("the 3D renderer stopped (signal " + std::to_string(WTERMSIG(status)) +
                "): VTK could not open an OpenGL window on the display");
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0 || png.size() < 8)
    throw Error("the 3D renderer failed (exit code " + std::to_string(WIFEXITED(status) ? WEXITSTATUS(status) : -1) +
                ")");
  return png;
}

}  // namespace mrsnake::reports
