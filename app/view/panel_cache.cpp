#include "app/view/panel_cache.h"

#include "pvrr/gl/gl.h"  // glad first

#include <backends/imgui_impl_opengl3.h>
#include <imgui.h>

#include <algorithm>
#include <vector>

namespace pvrr::app::view {

void drawListsOf(ImDrawData& dd, int first, int last) {
  if (first >= last) return;
  ImDrawData part = dd;
  std::vector<ImDrawList*> lists(dd.CmdLists + first, dd.CmdLists + last);
  part.CmdLists = lists.data();
  part.CmdListsCount = int(lists.size());
  part.TotalVtxCount = part.TotalIdxCount = 0;
  for (const ImDrawList* l : lists) {
    part.TotalVtxCount += l->VtxBuffer.Size;
    part.TotalIdxCount += l->IdxBuffer.Size;
  }
  ImGui_ImplOpenGL3_RenderDrawData(&part);
}

PanelCache::~PanelCache() {
  if (framebuffer_) glDeleteFramebuffers(1, &framebuffer_);
  if (texture_) glDeleteTextures(1, &texture_);
}

void PanelCache::shown(bool whole) {
  if (whole) {
    shown_valid_ = from_picture_;
    shown_picture_ = pictures_;
    shown_rect_ = rect_;
  }
  from_picture_ = false;
}

bool PanelCache::draw(ImDrawData& dd, const ImDrawList* panel, const PixelRect& rect, int width, int height,
                      bool may_keep) {
  from_picture_ = false;
  int at = -1;
  for (int i = 0; i < dd.CmdListsCount; ++i)
    if (dd.CmdLists[i] == panel) at = i;
  if (at < 0) {  // no panel this frame
    drawListsOf(dd, 0, dd.CmdListsCount);
    return false;
  }
  if (width != width_ || height != height_ || !texture_) {
    if (!framebuffer_) glGenFramebuffers(1, &framebuffer_);
    if (texture_) glDeleteTextures(1, &texture_);
    glGenTextures(1, &texture_);
    glBindTexture(GL_TEXTURE_2D, texture_);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, width, height, 0, GL_RGBA, GL_UNSIGNED_BYTE, nullptr);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glBindTexture(GL_TEXTURE_2D, 0);
    glBindFramebuffer(GL_FRAMEBUFFER, framebuffer_);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, texture_, 0);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    width_ = width;
    height_ = height;
    valid_ = false;
  }
  const auto now = std::chrono::steady_clock::now();
  const bool due = !valid_ || !(rect == rect_) ||
                   std::chrono::duration<double, std::milli>(now - made_).count() >= kPanelRefreshMs;
  if (may_keep && !due && shown_valid_ && shown_picture_ == pictures_ && shown_rect_ == rect &&
      at + 1 == dd.CmdListsCount) {
    // The window shows this picture here already, and nothing is drawn over it: the lists under it only (what
    // of them lies in the panel's rectangle the opaque panel hides, and it is not shown).
    drawListsOf(dd, 0, at);
    ++kept_;
    gl::checkGlError("drawing the lists under the kept panel");
    return true;
  }
  if (due) {
    glBindFramebuffer(GL_FRAMEBUFFER, framebuffer_);
    glDisable(GL_SCISSOR_TEST);
    const GLfloat clear[4] = {0, 0, 0, 0};
    glClearBufferfv(GL_COLOR, 0, clear);
    drawListsOf(dd, at, at + 1);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    valid_ = true;
    rect_ = rect;
    made_ = now;
    ++pictures_;
  }
  drawListsOf(dd, 0, at);  // under the panel
  // The panel's rectangle, as GL counts rows (bottom-up), copied from the picture.
  const PixelRect r{std::max(rect.x0, 0), std::max(rect.y0, 0), std::min(rect.x1, width), std::min(rect.y1, height)};
  if (!r.empty()) {
    glDisable(GL_SCISSOR_TEST);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, framebuffer_);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
    glBlitFramebuffer(r.x0, height - r.y1, r.x1, height - r.y0, r.x0, height - r.y1, r.x1, height - r.y0,
                      GL_COLOR_BUFFER_BIT, GL_NEAREST);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
  }
  ++copies_;
  drawListsOf(dd, at + 1, dd.CmdListsCount);  // over it
  from_picture_ = at + 1 == dd.CmdListsCount;
  gl::checkGlError("drawing the panel from its picture");
  return false;
}

}  // namespace pvrr::app::view
