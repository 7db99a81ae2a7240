#include "gl/shared_context.h"

namespace waxwork {
namespace {

class HeadlessSolverContext : public SolverGlContext {
public:
    explicit HeadlessSolverContext(HeadlessGlContext* borrowed) : context_(borrowed) {}
    HeadlessSolverContext() : owned_(std::make_unique<HeadlessGlContext>()), context_(owned_.get()) {}
    void make_current() override { context_->make_current(); }
    const GlApi& gl() const override { return context_->gl(); }

private:
    std::unique_ptr<HeadlessGlContext> owned_;
    HeadlessGlContext* context_;
};

}  // namespace

std::shared_ptr<SolverGlContext> open_headless_solver_context() { return std::make_shared<HeadlessSolverContext>(); }

std::shared_ptr<SolverGlContext> borrow_headless_solver_context(HeadlessGlContext& context) {
    return std::make_shared<HeadlessSolverContext>(&context);
}

}  // namespace waxwork
