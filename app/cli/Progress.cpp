#include "Progress.h"

#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace pneuma::app {

namespace {

std::atomic<bool> g_interrupted{false};
static_assert(std::atomic<bool>::is_always_lock_free, "the SIGINT handler writes the flag");
struct sigaction g_previous {};

void onSigint(int) {
  if (g_interrupted.load()) {
    // a second Ctrl-C: end now, as the default action would (both calls are async-signal-safe)
    signal(SIGINT, SIG_DFL);
    raise(SIGINT);
    return;
  }
  g_interrupted.store(true);
}

std::string formatSeconds(double s) {
  char buf[32];
  if (!std::isfinite(s)) return "--";
  if (s >= 3600.0)
    std::snprintf(buf, sizeof buf, "%dh%02dm", static_cast<int>(s / 3600),
                  static_cast<int>(std::fmod(s, 3600) / 60));
  else if (s >= 60.0)
    std::snprintf(buf, sizeof buf, "%dm%02ds", static_cast<int>(s / 60), static_cast<int>(std::fmod(s, 60)));
  else
    std::snprintf(buf, sizeof buf, "%.0fs", s);
  return buf;
}

}  // namespace

InterruptGuard::InterruptGuard() {
  g_interrupted.store(false);
  struct sigaction sa {};
  sa.sa_handler = onSigint;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, &g_previous);
}

InterruptGuard::~InterruptGuard() { sigaction(SIGINT, &g_previous, nullptr); }

bool InterruptGuard::isInterrupted() { return g_interrupted.load(); }

const std::atomic<bool>* InterruptGuard::flag() { return &g_interrupted; }

ProgressBar::ProgressBar(std::string label, double totalTime)
    : m_label(std::move(label)),
      m_total(totalTime),
      m_isTty(isatty(STDERR_FILENO) != 0),
      m_start(std::chrono::steady_clock::now()),
      m_lastDraw(m_start) {}

void ProgressBar::update(double t) {
  if (!m_isTty) return;
  const auto now = std::chrono::steady_clock::now();
  if (m_hasDrawn && now - m_lastDraw < std::chrono::milliseconds(100)) return;
  m_lastDraw = now;
  draw(t);
}

void ProgressBar::draw(double t) {
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - m_start).count();
  const double fraction = m_total > 0.0 ? std::clamp(t / m_total, 0.0, 1.0) : 1.0;
  const double rtf = wall > 0.0 ? t / wall : 0.0;
  const double eta = rtf > 0.0 ? (m_total - t) / rtf : NAN;
  constexpr int kWidth = 30;
  const int filled = static_cast<int>(fraction * kWidth);
  std::string bar(static_cast<std::size_t>(filled), '#');
  bar.resize(kWidth, '-');
  std::fprintf(stderr, "\r%s [%s] %5.1f/%.1f s  RTF %.2f  ETA %s   ", m_label.c_str(), bar.c_str(), t,
               m_total, rtf, formatSeconds(eta).c_str());
  std::fflush(stderr);
  m_hasDrawn = true;
}

void ProgressBar::finish() {
  if (!m_isTty || !m_hasDrawn) return;
  std::fprintf(stderr, "\r%*s\r", 100, "");
  std::fflush(stderr);
  m_hasDrawn = false;
}

}  // namespace pneuma::app
