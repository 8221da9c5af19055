#include "hand_written.h"

#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <vector>

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

namespace psys::bench {
namespace {

constexpr size_t kChunk = 8192;

// rt/rng.h's hash, as a stream: one draw per call.
struct Random {
    uint32_t counter = 1;
    static uint32_t pcg(uint32_t v) {
        uint32_t state = v * 747796405u + 2891336453u;
        uint32_t word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
        return (word >> 22u) ^ word;
    }
    float uniform() { return static_cast<float>(pcg(counter++) >> 8) * (1.0f / 16777216.0f); }
    float signedUniform() { return uniform() * 2 - 1; }
};

// The update loop over chunks of particles, on `threads` threads (0: every core).
class Chunked : public HandWritten {
protected:
    template <typename F>
    void forChunks(size_t n, F update) {
        size_t chunks = (n + kChunk - 1) / kChunk;
        auto chunk = [&](size_t c) { update(c * kChunk, std::min(n, (c + 1) * kChunk)); };
        if (threads_ == 1 || chunks < 2) {
            for (size_t c = 0; c < chunks; ++c) chunk(c);
            return;
        }
        if (!arena_ || arenaThreads_ != threads_) {
            arena_ = std::make_unique<tbb::task_arena>(threads_ ? static_cast<int>(threads_) : tbb::task_arena::automatic);
            arenaThreads_ = threads_;
        }
        arena_->execute([&] { tbb::parallel_for(size_t{0}, chunks, chunk); });
    }

    // Emission at `rate` per second: whole particles per step, the rest carried over.
    size_t due(double rate, float dt) {
        carried_ += rate * dt;
        double whole = std::floor(carried_);
        carried_ -= whole;
        return static_cast<size_t>(whole);
    }

    Random random_;

private:
    std::unique_ptr<tbb::task_arena> arena_;
    unsigned arenaThreads_ = 0;
    double carried_ = 0;
};

// Swap-with-last removal of the particles flagged in `dead`; `move(from, to)` moves one.
template <typename Move>
size_t compact(std::vector<uint8_t>& dead, size_t n, Move move) {
    size_t i = 0;
    while (i < n) {
        if (dead[i]) {
            --n;
            move(n, i);
            dead[i] = dead[n];
        } else {
            ++i;
        }
    }
    return n;
}

// The particles of a hand-written SoA effect: a float column per component, dead flags,
// a count; removal swaps the last particle in.
enum Column : size_t { kPx, kPy, kPz, kVx, kVy, kVz, kAge, kR, kG, kB, kA };

class SoAParticles {
public:
    SoAParticles(size_t columns, size_t capacity) : columns_(columns, std::vector<float>(capacity)), dead_(capacity) {}
    float* column(Column c) { return columns_[c].data(); }
    float& at(Column c, size_t i) { return columns_[c][i]; }
    uint8_t* dead() { return dead_.data(); }
    size_t live() const { return n_; }
    size_t room() const { return dead_.size() - n_; }
    size_t bytesPerUpdate() const { return 2 * columns_.size() * sizeof(float) + 1; }
    size_t add() { return n_++; }
    void removeDead() {
        n_ = compact(dead_, n_, [this](size_t from, size_t to) {
            for (auto& c : columns_) c[to] = c[from];
        });
    }

private:
    std::vector<std::vector<float>> columns_;
    std::vector<uint8_t> dead_;
    size_t n_ = 0;
};

// A velocity uniform in the cone of samples/fountain.psys.
void cone(Random& r, float& x, float& y, float& z) {
    float h = 12 * std::cbrt(r.uniform());
    float s = h / 3 * std::sqrt(r.uniform());
    float a = 6.2831853f * r.uniform();
    x = s * std::cos(a);
    y = h;
    z = s * std::sin(a);
}

// ---- fountain --------------------------------------------------------------------------

class FountainSoA : public Chunked {
public:
    FountainSoA(double population, size_t capacity) : population_(population), p_(11, capacity) {}
    size_t live() const override { return p_.live(); }
    size_t bytesPerUpdate() const override { return p_.bytesPerUpdate(); }

    void step(float dt) override {
        forChunks(p_.live(), [&](size_t begin, size_t end) { update(begin, end, dt); });
        p_.removeDead();
        size_t born = std::min(due(population_ / 3, dt), p_.room());
        for (size_t k = 0; k < born; ++k) {
            size_t i = p_.add();
            p_.at(kPx, i) = p_.at(kPy, i) = p_.at(kPz, i) = 0;
            cone(random_, p_.at(kVx, i), p_.at(kVy, i), p_.at(kVz, i));
            p_.at(kR, i) = 0.6f, p_.at(kG, i) = 0.8f, p_.at(kB, i) = 1, p_.at(kA, i) = 1, p_.at(kAge, i) = 0;
        }
    }

private:
    void update(size_t begin, size_t end, float dt) {
        float* __restrict px = p_.column(kPx);
        float* __restrict py = p_.column(kPy);
        float* __restrict pz = p_.column(kPz);
        float* __restrict vx = p_.column(kVx);
        float* __restrict vy = p_.column(kVy);
        float* __restrict vz = p_.column(kVz);
        float* __restrict r = p_.column(kR);
        float* __restrict g = p_.column(kG);
        float* __restrict b = p_.column(kB);
        float* __restrict a = p_.column(kA);
        float* __restrict age = p_.column(kAge);
        uint8_t* __restrict dead = p_.dead();
        const float fall = -9.8f * dt, fade = 0.5f * dt;
#pragma omp simd
        for (size_t i = begin; i < end; ++i) {
            float vy1 = vy[i] + fall;
            float y1 = py[i] + vy1 * dt;
            bool below = y1 < 0;
            px[i] += vx[i] * dt;
            pz[i] += vz[i] * dt;
            py[i] = below ? -y1 * 0.5f : y1;
            vy[i] = below ? -vy1 * 0.5f : vy1;
            r[i] += (0.1f - r[i]) * fade;
            g[i] += (0.1f - g[i]) * fade;
            b[i] += (0.1f - b[i]) * fade;
            a[i] += (0.0f - a[i]) * fade;
            float t = age[i] + dt;
            age[i] = t;
            dead[i] = t >= 3.0f;
        }
    }

    double population_;
    SoAParticles p_;
};

// The tutorials' particle: everything any effect might use, 64 bytes.
struct alignas(64) Particle {
    float pos[3], vel[3], color[4];
    float age, size, lifetime, mass, rotation, spin;
};
static_assert(sizeof(Particle) == 64);

class AoS : public Chunked {
protected:
    AoS(size_t capacity) : particles_(capacity), dead_(capacity), capacity_(capacity) {}
    size_t live() const override { return n_; }
    size_t bytesPerUpdate() const override { return 2 * sizeof(Particle) + 1; }
    void compactAndKeep() {
        n_ = compact(dead_, n_, [this](size_t from, size_t to) { particles_[to] = particles_[from]; });
    }
    Particle& born() { return particles_[n_++]; }
    size_t room() const { return capacity_ - n_; }

    std::vector<Particle> particles_;
    std::vector<uint8_t> dead_;
    size_t capacity_, n_ = 0;
};

class FountainAoS : public AoS {
public:
    FountainAoS(double population, size_t capacity) : AoS(capacity), population_(population) {}
    void step(float dt) override {
        forChunks(n_, [&](size_t begin, size_t end) { update(begin, end, dt); });
        compactAndKeep();
        size_t count = std::min(due(population_ / 3, dt), room());
        for (size_t k = 0; k < count; ++k) {
            Particle& p = born();
            p = Particle{};
            cone(random_, p.vel[0], p.vel[1], p.vel[2]);
            p.color[0] = 0.6f, p.color[1] = 0.8f, p.color[2] = 1, p.color[3] = 1;
            p.size = 2, p.lifetime = 3, p.mass = 1;
        }
    }

private:
    void update(size_t begin, size_t end, float dt) {
        Particle* __restrict p = particles_.data();
        uint8_t* __restrict dead = dead_.data();
        const float fall = -9.8f * dt, fade = 0.5f * dt;
#pragma omp simd
        for (size_t i = begin; i < end; ++i) {
            float vy1 = p[i].vel[1] + fall;
            float y1 = p[i].pos[1] + vy1 * dt;
            bool below = y1 < 0;
            p[i].pos[0] += p[i].vel[0] * dt;
            p[i].pos[2] += p[i].vel[2] * dt;
            p[i].pos[1] = below ? -y1 * 0.5f : y1;
            p[i].vel[1] = below ? -vy1 * 0.5f : vy1;
            for (int c = 0; c < 3; ++c) p[i].color[c] += (0.1f - p[i].color[c]) * fade;
            p[i].color[3] += (0.0f - p[i].color[3]) * fade;
            float t = p[i].age + dt;
            p[i].age = t;
            dead[i] = t >= p[i].lifetime;
        }
    }
    double population_;
};

// ---- fire --------------------------------------------------------------------------------

class FireSoA : public Chunked {
public:
    FireSoA(double rate, size_t capacity) : rate_(rate), p_(7, capacity) {}
    size_t live() const override { return p_.live(); }
    size_t bytesPerUpdate() const override { return p_.bytesPerUpdate(); }

    void step(float dt) override {
        forChunks(p_.live(), [&](size_t begin, size_t end) { update(begin, end, dt); });
        p_.removeDead();
        size_t born = std::min(due(rate_, dt), p_.room());
        for (size_t k = 0; k < born; ++k) {
            size_t i = p_.add();
            p_.at(kPx, i) = random_.signedUniform(), p_.at(kPy, i) = 0, p_.at(kPz, i) = random_.signedUniform();
            p_.at(kVx, i) = 3 * random_.signedUniform(), p_.at(kVy, i) = 3 * random_.signedUniform();
            p_.at(kVz, i) = 3 * random_.signedUniform(), p_.at(kAge, i) = 0;
        }
    }

private:
    void update(size_t begin, size_t end, float dt) {
        float* __restrict px = p_.column(kPx);
        float* __restrict py = p_.column(kPy);
        float* __restrict pz = p_.column(kPz);
        float* __restrict vx = p_.column(kVx);
        float* __restrict vy = p_.column(kVy);
        float* __restrict vz = p_.column(kVz);
        float* __restrict age = p_.column(kAge);
        uint8_t* __restrict dead = p_.dead();
#pragma omp simd
        for (size_t i = begin; i < end; ++i) {
            float temp = 100 * std::exp(-0.3f * age[i]);
            float ay = -9.82f * 0.2f - vy[i] + std::max(0.0f, temp / 3 - 15);
            px[i] += vx[i] * dt;
            float y = py[i] + vy[i] * dt;
            py[i] = y;
            pz[i] += vz[i] * dt;
            vx[i] -= vx[i] * dt;
            vy[i] += ay * dt;
            vz[i] -= vz[i] * dt;
            age[i] += dt;
            dead[i] = y < 0;
        }
    }

    double rate_;
    SoAParticles p_;
};

class FireAoS : public AoS {
public:
    FireAoS(double rate, size_t capacity) : AoS(capacity), rate_(rate) {}
    void step(float dt) override {
        forChunks(n_, [&](size_t begin, size_t end) { update(begin, end, dt); });
        compactAndKeep();
        size_t count = std::min(due(rate_, dt), room());
        for (size_t k = 0; k < count; ++k) {
            Particle& p = born();
            p = Particle{};
            p.pos[0] = random_.signedUniform(), p.pos[2] = random_.signedUniform();
            for (float& v : p.vel) v = 3 * random_.signedUniform();
            p.size = 2, p.mass = 1;
        }
    }

private:
    void update(size_t begin, size_t end, float dt) {
        Particle* __restrict p = particles_.data();
        uint8_t* __restrict dead = dead_.data();
#pragma omp simd
        for (size_t i = begin; i < end; ++i) {
            float temp = 100 * std::exp(-0.3f * p[i].age);
            float ay = -9.82f * 0.2f - p[i].vel[1] + std::max(0.0f, temp / 3 - 15);
            for (int c = 0; c < 3; ++c) p[i].pos[c] += p[i].vel[c] * dt;
            p[i].vel[0] -= p[i].vel[0] * dt;
            p[i].vel[1] += ay * dt;
            p[i].vel[2] -= p[i].vel[2] * dt;
            float ct = temp / 70;  // the colour the tutorials keep in the particle
            p[i].color[0] = 1, p[i].color[1] = ct / 2, p[i].color[2] = ct / 4, p[i].color[3] = ct;
            p[i].age += dt;
            dead[i] = p[i].pos[1] < 0;
        }
    }
    double rate_;
};

// ---- fireworks ---------------------------------------------------------------------------

struct Rocket {
    float pos[3], vel[3];
    double carried = 0;  // sparks due
};

// Rockets are few and serial; the sparks are the work.
class FireworksBase : public Chunked {
protected:
    explicit FireworksBase(double sparks) : sparks_(sparks) {}

    // Launches rockets, moves them, kills the falling ones; `spark(pos)` emits one spark.
    template <typename Spark>
    void rockets(float dt, Spark spark) {
        for (size_t k = due(10, dt); k > 0; --k)
            rockets_.push_back({{0, 0, 0}, {random_.signedUniform() * 2, 15, random_.signedUniform() * 2}});
        for (size_t i = 0; i < rockets_.size();) {
            Rocket& r = rockets_[i];
            for (int c = 0; c < 3; ++c) r.pos[c] += r.vel[c] * dt;
            r.vel[1] += -9.82f * 0.3f * dt;
            if (r.vel[1] < 0) {
                rockets_[i] = rockets_.back();
                rockets_.pop_back();
                continue;
            }
            r.carried += sparks_ * dt;
            double whole = std::floor(r.carried);
            r.carried -= whole;
            for (size_t s = 0; s < static_cast<size_t>(whole); ++s) spark(r.pos);
            ++i;
        }
    }

    double sparks_;
    std::vector<Rocket> rockets_;
};

class FireworksSoA : public FireworksBase {
public:
    FireworksSoA(double sparks, size_t capacity) : FireworksBase(sparks), p_(7, capacity) {}
    size_t live() const override { return p_.live(); }
    size_t bytesPerUpdate() const override { return p_.bytesPerUpdate(); }

    void step(float dt) override {
        forChunks(p_.live(), [&](size_t begin, size_t end) { update(begin, end, dt); });
        p_.removeDead();
        rockets(dt, [this](const float* pos) {
            if (p_.room() == 0) return;
            size_t i = p_.add();
            p_.at(kPx, i) = pos[0], p_.at(kPy, i) = pos[1], p_.at(kPz, i) = pos[2];
            p_.at(kVx, i) = p_.at(kVy, i) = p_.at(kVz, i) = p_.at(kAge, i) = 0;
        });
    }

private:
    void update(size_t begin, size_t end, float dt) {
        float* __restrict px = p_.column(kPx);
        float* __restrict py = p_.column(kPy);
        float* __restrict pz = p_.column(kPz);
        float* __restrict vx = p_.column(kVx);
        float* __restrict vy = p_.column(kVy);
        float* __restrict vz = p_.column(kVz);
        float* __restrict age = p_.column(kAge);
        uint8_t* __restrict dead = p_.dead();
        const float fall = -9.82f * 0.4f * dt;
#pragma omp simd
        for (size_t i = begin; i < end; ++i) {
            px[i] += vx[i] * dt;
            py[i] += vy[i] * dt;
            pz[i] += vz[i] * dt;
            vy[i] += fall;
            float t = age[i] + dt;
            age[i] = t;
            dead[i] = t > 1.0f;
        }
    }

    SoAParticles p_;
};

class FireworksAoS : public FireworksBase {
public:
    FireworksAoS(double sparks, size_t capacity) : FireworksBase(sparks), particles_(capacity), dead_(capacity) {}
    size_t live() const override { return n_; }
    size_t bytesPerUpdate() const override { return 2 * sizeof(Particle) + 1; }

    void step(float dt) override {
        forChunks(n_, [&](size_t begin, size_t end) { update(begin, end, dt); });
        n_ = compact(dead_, n_, [this](size_t from, size_t to) { particles_[to] = particles_[from]; });
        rockets(dt, [this](const float* pos) {
            if (n_ == particles_.size()) return;
            Particle& p = particles_[n_++];
            p = Particle{};
            for (int c = 0; c < 3; ++c) p.pos[c] = pos[c];
            p.color[1] = 1, p.color[3] = 1, p.size = 2, p.lifetime = 1, p.mass = 1;
        });
    }

private:
    void update(size_t begin, size_t end, float dt) {
        Particle* __restrict p = particles_.data();
        uint8_t* __restrict dead = dead_.data();
        const float fall = -9.82f * 0.4f * dt;
#pragma omp simd
        for (size_t i = begin; i < end; ++i) {
            for (int c = 0; c < 3; ++c) p[i].pos[c] += p[i].vel[c] * dt;
            p[i].vel[1] += fall;
            float t = p[i].age + dt;
            p[i].age = t;
            p[i].color[1] = 1 - t;  // green to black in a second
            dead[i] = t > p[i].lifetime;
        }
    }

    std::vector<Particle> particles_;
    std::vector<uint8_t> dead_;
    size_t n_ = 0;
};

}  // namespace

std::unique_ptr<HandWritten> makeHandWritten(const std::string& effect, bool soa, double knob, size_t capacity) {
    if (effect == "fountain") {
        if (soa) return std::make_unique<FountainSoA>(knob, capacity);
        return std::make_unique<FountainAoS>(knob, capacity);
    }
    if (effect == "fire") {
        if (soa) return std::make_unique<FireSoA>(knob, capacity);
        return std::make_unique<FireAoS>(knob, capacity);
    }
    if (effect == "fireworks") {
        if (soa) return std::make_unique<FireworksSoA>(knob, capacity);
        return std::make_unique<FireworksAoS>(knob, capacity);
    }
    throw std::invalid_argument("no hand-written " + effect);
}

}  // namespace psys::bench
