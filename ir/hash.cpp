#include "ir/hash.h"

#include <cstring>

#include <fmt/format.h>

namespace psys::ir {

namespace {

uint64_t mix(uint64_t x) {  // splitmix64's finaliser
    x ^= x >> 30;
    x *= 0xBF58476D1CE4E5B9ull;
    x ^= x >> 27;
    x *= 0x94D049BB133111EBull;
    x ^= x >> 31;
    return x;
}

}  // namespace

std::string Hash128::hex() const { return fmt::format("{:016x}{:016x}", high, low); }

Hasher& Hasher::add(uint64_t w) {
    ++count_;
    a_ = mix(a_ ^ w) + count_;
    b_ = mix(b_ + (w ^ 0xD6E8FEB86659FD93ull)) ^ (a_ >> 17);
    return *this;
}

Hasher& Hasher::add(std::string_view bytes) {
    add(bytes.size());
    for (size_t i = 0; i < bytes.size(); i += 8) {
        uint64_t w = 0;
        std::memcpy(&w, bytes.data() + i, std::min<size_t>(8, bytes.size() - i));
        add(w);
    }
    return *this;
}

Hash128 Hasher::finish() const { return {mix(a_ ^ count_), mix(b_ + a_)}; }

Hash128 structuralHash(const Kernel& k) {
    Hasher h;
    h.add(static_cast<uint64_t>(k.kind)).add(static_cast<uint64_t>(static_cast<int64_t>(k.site))).add(k.size());
    for (const Inst& i : k.insts()) {
        h.add(static_cast<uint64_t>(i.op) | static_cast<uint64_t>(i.type.kind) << 8 | static_cast<uint64_t>(i.type.width) << 16);
        h.add(static_cast<uint64_t>(static_cast<uint32_t>(i.attr)) | static_cast<uint64_t>(static_cast<uint32_t>(i.attr2)) << 32);
        if (i.op == Op::Const) {
            uint64_t bits[2];
            std::memcpy(bits, i.constant.data(), sizeof bits);
            h.add(bits[0]).add(bits[1]);
        }
        h.add(i.operands.size());
        for (ValueId o : i.operands) h.add(o);
        h.add(std::string_view(reinterpret_cast<const char*>(i.lanes.data()), i.lanes.size()));
    }
    h.add(k.yields.size());
    for (const Yield& y : k.yields)
        h.add(static_cast<uint64_t>(y.kind) | static_cast<uint64_t>(static_cast<uint32_t>(y.index)) << 8 |
              static_cast<uint64_t>(static_cast<uint32_t>(y.sub)) << 40)
            .add(y.value);
    return h.finish();
}

}  // namespace psys::ir
