#include "panel.h"

#include <epoxy/gl.h>

#include <cstdlib>
#include <filesystem>

#include <GLFW/glfw3.h>
#include <fmt/format.h>
#include <imgui.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>

#include "keys.h"
#include "viewer.h"

namespace psys::viewer {

namespace {

// What the panel writes beyond ASCII: Latin-1 (×, ÷, °), Greek, punctuation (…, –, “”),
// arrows and mathematical operators (≤, ≈, √).
const ImWchar kGlyphs[] = {0x0020, 0x00FF, 0x0370, 0x03FF, 0x2000, 0x206F, 0x2190, 0x21FF, 0x2200, 0x22FF, 0};

// A font with those glyphs: PSYS_VIEW_FONT, else DejaVu Sans (fonts-dejavu-core, which
// scripts/setup.sh installs); without one, ImGui's own font, ASCII only ("…" shows "?").
void loadFont(ImGuiIO& io) {
    std::vector<std::string> candidates;
    if (const char* v = std::getenv("PSYS_VIEW_FONT"); v && *v) candidates.push_back(v);
    candidates.push_back("/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf");
    candidates.push_back("/usr/share/fonts/dejavu/DejaVuSans.ttf");
    for (const std::string& path : candidates) {
        std::error_code ignored;
        if (std::filesystem::is_regular_file(path, ignored) &&
            io.Fonts->AddFontFromFileTTF(path.c_str(), 15.0f, nullptr, kGlyphs))
            return;
    }
    io.Fonts->AddFontDefault();
}

}  // namespace

bool Panel::hasGlyph(unsigned codepoint) const {
    ImFont* font = ImGui::GetIO().Fonts->Fonts.empty() ? nullptr : ImGui::GetIO().Fonts->Fonts[0];
    return font && font->FindGlyphNoFallback(static_cast<ImWchar>(codepoint)) != nullptr;
}

Panel::Panel(Viewer& viewer, Surface& surface) : viewer_(viewer), surface_(surface) {
    IMGUI_CHECKVERSION();
    context_ = ImGui::CreateContext();
    ImGuiIO& io = ImGui::GetIO();
    io.IniFilename = nullptr;  // no imgui.ini next to the user's files
    loadFont(io);
    ImGui::StyleColorsDark();
    ImGui::GetStyle().Alpha = 0.94f;
    // The window's input callbacks are installed first (tools/viewer/main.cpp): ImGui's
    // chain to them.
    if (surface_.window()) ImGui_ImplGlfw_InitForOpenGL(surface_.window(), true);
    ImGui_ImplOpenGL3_Init("#version 450");
    seed_ = static_cast<int>(viewer_.session().options().system.seed);
}

Panel::~Panel() {
    ImGui_ImplOpenGL3_Shutdown();
    if (surface_.window()) ImGui_ImplGlfw_Shutdown();
    ImGui::DestroyContext(context_);
}

bool Panel::wantsMouse() const { return ImGui::GetIO().WantCaptureMouse; }
bool Panel::wantsKeyboard() const { return ImGui::GetIO().WantCaptureKeyboard; }

std::vector<float> Panel::triggerArgs(size_t index) const {
    const auto& triggers = viewer_.session_->system().module().triggers;
    if (index >= triggers.size()) return {};
    auto it = args_.find(triggers[index].name);
    return it == args_.end() ? std::vector<float>{} : it->second;
}

void Panel::draw() {
    ImGui_ImplOpenGL3_NewFrame();
    ImGuiIO& io = ImGui::GetIO();
    if (surface_.window()) {
        ImGui_ImplGlfw_NewFrame();
    } else {  // offscreen: the frame's size, a frame's time
        io.DisplaySize = ImVec2(static_cast<float>(surface_.width()), static_cast<float>(surface_.height()));
        io.DeltaTime = 1.0f / 60;
    }
    ImGui::NewFrame();
    if (visible) {
        controls();
        stats();
    }
    help();
    diagnostics();
    ImGui::Render();
    surface_.bind();
    ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
}

void Panel::controls() {
    ImGui::SetNextWindowPos(ImVec2(10, 10), ImGuiCond_FirstUseEver);
    ImGui::SetNextWindowSize(ImVec2(340, 0), ImGuiCond_FirstUseEver);
    ImGui::Begin("psys");
    host::Session& session = viewer_.session();
    ImGui::TextUnformatted(session.path().c_str());
    // Time.
    ImGui::Checkbox("pause (space)", &viewer_.paused_);
    ImGui::SameLine();
    if (ImGui::Button("step (S)")) viewer_.stepOnce_ = true;
    SimClock::Settings& clock = viewer_.clock_.settings();
    float scale = static_cast<float>(clock.scale);
    if (ImGui::SliderFloat("time scale (+ -)", &scale, 1.0f / 64, 16, "%.3g", ImGuiSliderFlags_Logarithmic))
        clock.scale = scale;
    bool real = !clock.fixed;
    if (ImGui::Checkbox("real time (T)", &real)) {
        clock.fixed = !real;
        viewer_.clock_.resetDebt();
    }
    ImGui::InputInt("seed", &seed_);
    ImGui::SameLine();
    if (ImGui::Button("restart")) viewer_.restart(static_cast<uint32_t>(seed_));
    // Backend and drawing.
    std::string current = session.backend().name();
    if (ImGui::BeginCombo("backend", current.c_str())) {
        for (const std::string& name : host::backendNames())
            if (ImGui::Selectable(name.c_str(), name == current) && name != current) {
                host::BackendChoice choice = session.options().backend;
                choice.name = name;
                if (auto error = session.switchBackend(choice)) viewer_.diagnostics_ = *error;
            }
        ImGui::EndCombo();
    }
    bool additive = viewer_.options_.blend == Blend::Additive;
    if (ImGui::RadioButton("additive", additive)) viewer_.options_.blend = Blend::Additive;
    ImGui::SameLine();
    if (ImGui::RadioButton("alpha (B)", !additive)) viewer_.options_.blend = Blend::Alpha;
    ImGui::SameLine();
    ImGui::Checkbox("grid (G)", &viewer_.options_.grid);
    ImGui::Checkbox("glow (L)", &viewer_.options_.glow.on);
    if (viewer_.options_.glow.on) {
        ImGui::SameLine();
        ImGui::SetNextItemWidth(120);
        ImGui::SliderFloat("strength", &viewer_.options_.glow.strength, 0.0f, 2.0f, "%.2f");
    }
    if (ImGui::Button("frame what is alive (F)")) viewer_.frameAlive();
    ImGui::SameLine();
    if (ImGui::Button("reset camera (R)")) viewer_.camera_.reset();
    externs();
    triggers();
    ImGui::End();
}

void Panel::externs() {
    rt::System& system = viewer_.session().system();
    const auto& list = system.module().externs;
    if (list.empty() || !ImGui::CollapsingHeader("externs", ImGuiTreeNodeFlags_DefaultOpen)) return;
    for (const ir::Extern& e : list) {
        ImGui::PushID(e.name.c_str());
        std::array<float, 4> v = system.externValue(e.name)->f;
        float low = e.low ? (*e.low)[0] : -10, high = e.high ? (*e.high)[0] : 10;
        bool changed = false;
        const char* label = e.name.c_str();
        if (e.type.isBool()) {
            bool on = v[0] != 0;
            changed = ImGui::Checkbox(label, &on);
            v[0] = on ? 1.0f : 0.0f;
        } else if (e.spelling == "color" && e.type.width >= 3) {
            changed = e.type.width == 4 ? ImGui::ColorEdit4(label, v.data()) : ImGui::ColorEdit3(label, v.data());
        } else if (e.type.width == 1) {
            changed = e.low ? ImGui::SliderFloat(label, v.data(), low, high) : ImGui::DragFloat(label, v.data(), 0.05f);
        } else if (e.low) {
            switch (e.type.width) {
                case 2: changed = ImGui::SliderFloat2(label, v.data(), low, high); break;
                case 3: changed = ImGui::SliderFloat3(label, v.data(), low, high); break;
                default: changed = ImGui::SliderFloat4(label, v.data(), low, high); break;
            }
        } else {
            switch (e.type.width) {
                case 2: changed = ImGui::DragFloat2(label, v.data(), 0.05f); break;
                case 3: changed = ImGui::DragFloat3(label, v.data(), 0.05f); break;
                default: changed = ImGui::DragFloat4(label, v.data(), 0.05f); break;
            }
        }
        ImGui::SameLine();
        if (ImGui::SmallButton("reset")) {
            v = e.defaultValue;
            changed = true;
        }
        if (changed) system.setExtern(e.name, std::span<const float>(v.data(), static_cast<size_t>(e.type.width)));
        ImGui::PopID();
    }
}

void Panel::triggers() {
    const auto& list = viewer_.session().system().module().triggers;
    if (list.empty() || !ImGui::CollapsingHeader("triggers", ImGuiTreeNodeFlags_DefaultOpen)) return;
    for (size_t i = 0; i < list.size(); ++i) {
        const ir::Trigger& t = list[i];
        ImGui::PushID(t.name.c_str());
        std::vector<float>& args = args_[t.name];
        size_t width = 0;
        for (const ir::Param& p : t.hostParams()) width += static_cast<size_t>(p.type.width);
        args.resize(width, 0);
        size_t at = 0;
        for (const ir::Param& p : t.hostParams()) {
            float* x = args.data() + at;
            switch (p.type.width) {
                case 1: ImGui::DragFloat(p.name.c_str(), x, 0.05f); break;
                case 2: ImGui::DragFloat2(p.name.c_str(), x, 0.05f); break;
                case 3: ImGui::DragFloat3(p.name.c_str(), x, 0.05f); break;
                default: ImGui::DragFloat4(p.name.c_str(), x, 0.05f); break;
            }
            at += static_cast<size_t>(p.type.width);
        }
        std::string label = i < 9 ? fmt::format("fire {} ({})", t.name, i + 1) : "fire " + t.name;
        if (ImGui::Button(label.c_str())) viewer_.fire(t.name, args);
        ImGui::PopID();
    }
}

void Panel::stats() {
    const Viewer::FrameStats& f = viewer_.stats_;
    ImGuiIO& io = ImGui::GetIO();
    ImGui::SetNextWindowPos(ImVec2(io.DisplaySize.x - 10, 10), ImGuiCond_Always, ImVec2(1, 0));
    ImGui::SetNextWindowBgAlpha(0.6f);
    ImGui::Begin("stats", nullptr, ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_AlwaysAutoResize |
                                        ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_NoFocusOnAppearing);
    host::Session& session = viewer_.session();
    ImGui::Text("%.0f fps, frame %.2f ms (%s)", viewer_.fps_, f.frameSeconds * 1e3, session.backend().name().c_str());
    const SimClock& clock = viewer_.clock_;
    ImGui::Text("time %.3f s%s, %d step%s of %.2f ms this frame%s", viewer_.session().system().time(),
                viewer_.paused_ ? " (paused)" : "", f.steps, f.steps == 1 ? "" : "s", clock.stepSeconds() * 1e3,
                clock.settings().fixed ? " (a step a frame)" : "");
    if (clock.cappedFrames())
        ImGui::TextColored(ImVec4(1, 0.7f, 0.3f, 1), "behind real time: %llu frames capped at %d steps, %.2f s let go",
                           static_cast<unsigned long long>(clock.cappedFrames()), clock.settings().maxSteps, clock.dropped());
    const rt::Stats &a = f.before, &b = f.after;
    ImGui::Text("step %.2f ms: loops %.2f, kills/emissions %.2f, creation %.2f", f.stepSeconds * 1e3,
                (b.loopSeconds - a.loopSeconds) * 1e3, (b.emitSeconds - a.emitSeconds) * 1e3,
                (b.createSeconds - a.createSeconds) * 1e3);
    // draw(): what the step did not render as it went (rt/system_draw.h); GL: uploading and drawing.
    ImGui::Text("drawing %.2f ms (draw() %.2f)", f.glSeconds * 1e3, (b.drawSeconds - a.drawSeconds) * 1e3);
    ImGui::Text("last build %.1f ms", viewer_.lastCompileSeconds_ * 1e3);
    if (viewer_.lastReloadSeconds_) ImGui::Text("last reload: %.1f ms from save", *viewer_.lastReloadSeconds_ * 1e3);
    if (const auto& h = viewer_.lastHitch_)
        ImGui::Text("its slowest frame %.1f ms, %.1fx a normal one (%.1f ms)", h->worstSeconds * 1e3,
                    h->worstSeconds / std::max(h->normalSeconds, 1e-9), h->normalSeconds * 1e3);
    if (!viewer_.shotNote_.empty()) ImGui::TextWrapped("%s", viewer_.shotNote_.c_str());
    if (!viewer_.reloadNote_.empty()) ImGui::TextWrapped("%s", viewer_.reloadNote_.c_str());
    if (ImGui::BeginTable("types", 7, ImGuiTableFlags_SizingFixedFit)) {
        for (const char* h : {"shown", "solo", "type", "live", "created", "killed", "dropped"}) ImGui::TableSetupColumn(h);
        ImGui::TableHeadersRow();
        for (const rt::TypeStats& t : b.types) {
            ImGui::PushID(t.name.c_str());
            ImGui::TableNextRow();
            typeVisibility(t.name);
            ImGui::TableNextColumn();
            ImGui::TextUnformatted(t.name.c_str());
            for (uint64_t n : {static_cast<uint64_t>(t.live), t.created, t.killed, t.dropped}) {
                ImGui::TableNextColumn();
                ImGui::Text("%llu", static_cast<unsigned long long>(n));
            }
            ImGui::PopID();
        }
        ImGui::EndTable();
    }
    for (const rt::TypeStats& t : b.types)
        if (t.unstable)
            ImGui::TextColored(ImVec4(1, 0.45f, 0.3f, 1),
                               "%s: %llu updates beyond what its integrator holds (k*dt past the stability limit, or "
                               "bs3's tolerance in its last try): use @step or @integrator(exponential)",
                               t.name.c_str(), static_cast<unsigned long long>(t.unstable));
    if (b.rejectedSteps || b.nonFiniteExterns || b.invalidEmissions || b.nonFiniteRender)
        ImGui::TextColored(ImVec4(1, 0.7f, 0.3f, 1), "rejected steps %llu, non-finite externs %llu, invalid emissions %llu, "
                           "points not drawn (non-finite) %llu",
                           static_cast<unsigned long long>(b.rejectedSteps), static_cast<unsigned long long>(b.nonFiniteExterns),
                           static_cast<unsigned long long>(b.invalidEmissions), static_cast<unsigned long long>(b.nonFiniteRender));
    if (b.clampedEmissions)
        ImGui::TextColored(ImVec4(1, 0.7f, 0.3f, 1), "emissions asking for more than 1e18 objects (taken as 1e18): %llu",
                           static_cast<unsigned long long>(b.clampedEmissions));
    ImGui::End();
}

// A type's row of the stats: drawn or hidden, and solo (only it drawn; again: all).
void Panel::typeVisibility(const std::string& name) {
    // Shown while it draws (hidden, or another solo: not).
    ImGui::TableNextColumn();
    bool shown = !viewer_.hidden_.count(name);
    ImGui::BeginDisabled(!viewer_.solo_.empty());
    if (ImGui::Checkbox("##shown", &shown)) viewer_.hide(name, !shown);
    ImGui::EndDisabled();
    ImGui::TableNextColumn();
    bool solo = viewer_.solo_ == name;
    if (ImGui::Checkbox("##solo", &solo)) viewer_.solo(solo ? name : "");
}

// F1 or ?: the keys (tools/viewer/keys.h), over the middle of the frame.
void Panel::help() {
    if (!viewer_.help_) return;
    ImGuiIO& io = ImGui::GetIO();
    ImGui::SetNextWindowPos(ImVec2(io.DisplaySize.x * 0.5f, io.DisplaySize.y * 0.5f), ImGuiCond_Always, ImVec2(0.5f, 0.5f));
    ImGui::SetNextWindowBgAlpha(0.9f);
    ImGui::Begin("keys (F1 or ? closes)", &viewer_.help_,
                 ImGuiWindowFlags_NoCollapse | ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_AlwaysAutoResize);
    if (ImGui::BeginTable("keys", 2, ImGuiTableFlags_SizingFixedFit | ImGuiTableFlags_RowBg)) {
        for (const KeyBinding& b : keyBindings()) {
            ImGui::TableNextRow();
            ImGui::TableNextColumn();
            ImGui::TextUnformatted(b.keys.c_str());
            ImGui::TableNextColumn();
            ImGui::TextUnformatted(b.does.c_str());
        }
        ImGui::EndTable();
    }
    ImGui::TextUnformatted("Saving the file reloads it; the panel's table shows, hides or solos each type.");
    ImGui::End();
}

// An edit that does not compile: its errors, as psysc check prints them, until a good save
// (at most 40% of the window's height; more scroll).
void Panel::diagnostics() {
    if (viewer_.diagnostics_.empty()) return;
    ImGuiIO& io = ImGui::GetIO();
    ImGui::SetNextWindowPos(ImVec2(10, io.DisplaySize.y - 10), ImGuiCond_Always, ImVec2(0, 1));
    // At most 40% of the window: many errors scroll rather than cover the scene.
    ImGui::SetNextWindowSizeConstraints(ImVec2(io.DisplaySize.x - 20, 0),
                                        ImVec2(io.DisplaySize.x - 20, std::max(80.0f, io.DisplaySize.y * 0.4f)));
    ImGui::PushStyleColor(ImGuiCol_WindowBg, ImVec4(0.25f, 0.05f, 0.05f, 0.92f));
    ImGui::Begin("the edit does not compile; the system keeps running", nullptr,
                 ImGuiWindowFlags_NoCollapse | ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_AlwaysAutoResize);
    ImGui::TextUnformatted(viewer_.diagnostics_.c_str());
    ImGui::End();
    ImGui::PopStyleColor();
}

}  // namespace psys::viewer
