#include "editor/view_cache.h"

#include "base/error.h"

namespace waxwork {

ViewCache::~ViewCache() { release(); }

void ViewCache::release() {
    if (framebuffer_) gl_.DeleteFramebuffers(1, &framebuffer_);
    if (colour_) gl_.DeleteRenderbuffers(1, &colour_);
    framebuffer_ = colour_ = 0;
    width_ = height_ = 0;
    valid_ = false;
}

GLuint ViewCache::begin_update(const ViewKey& key) {
    if (key.width != width_ || key.height != height_ || !framebuffer_) {
        release();
        gl_.GenFramebuffers(1, &framebuffer_);
        gl_.GenRenderbuffers(1, &colour_);
        gl_.BindRenderbuffer(GL_RENDERBUFFER, colour_);
        gl_.RenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, key.width, key.height);
        gl_.BindFramebuffer(GL_FRAMEBUFFER, framebuffer_);
        gl_.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, colour_);
        const GLenum status = gl_.CheckFramebufferStatus(GL_FRAMEBUFFER);
        gl_.BindFramebuffer(GL_FRAMEBUFFER, 0);
        if (status != GL_FRAMEBUFFER_COMPLETE) {
            release();
            throw Error("view cache: the framebuffer is incomplete");
        }
        width_ = key.width;
        height_ = key.height;
    }
    key_ = key;
    valid_ = true;
    return framebuffer_;
}

void ViewCache::blit(GLuint target, int x, int y) const {
    if (!valid_) return;
    gl_.BindFramebuffer(GL_READ_FRAMEBUFFER, framebuffer_);
    gl_.BindFramebuffer(GL_DRAW_FRAMEBUFFER, target);
    gl_.BlitFramebuffer(0, 0, width_, height_, x, y, x + width_, y + height_, GL_COLOR_BUFFER_BIT, GL_NEAREST);
    gl_.BindFramebuffer(GL_FRAMEBUFFER, target);
}

}  // namespace waxwork
