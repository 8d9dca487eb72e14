// The prepared database's file layout (database.cpp; docs/prep.md "The database file"): what a
// tool that edits such a file — the fuzz target, which repairs the checksum of a mutated file so
// that its mutations reach the records — needs besides scene.h's saveDatabase / loadDatabase.
#pragma once

#include <cstddef>
#include <cstdint>

namespace sv::formats::detail {

// The header's size; the payload follows it.
inline constexpr size_t kDatabaseHeaderBytes = 64;
inline constexpr size_t kDatabasePayloadBytesAt = 16;  // the payload's size, 8 bytes
inline constexpr size_t kDatabaseChecksumAt = 24;

// The payload's checksum: h = 14695981039346656037; for each 8-byte little-endian word w of the
// payload (the last zero-padded) h = (h ⊕ w) · 1099511628211 mod 2^64; then h ⊕= h >> 29.
uint64_t databaseChecksum(const char* payload, size_t bytes);

}  // namespace sv::formats::detail
