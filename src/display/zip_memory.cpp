// Zip archives in memory: minizip's I/O callbacks (ioapi.h, zlib_filefunc64_def) over a byte
// string, so that neither the reader nor the writer touches the file system.
// Based on: PKWARE APPNOTE.TXT 6.3 (the zip format: local headers, central directory, CRC-32);
// minizip 1.1's unzip.h and zip.h for the calls.
#include "display/zip_memory.h"

#include <minizip/unzip.h>
#include <minizip/zip.h>

#include <fmt/format.h>

#include <algorithm>
#include <cstring>

namespace sv::display::detail {

// The byte string minizip reads or writes, and the position it is at.
struct ZipStream {
  const std::string* in = nullptr;  // reading
  std::string* out = nullptr;       // writing
  uint64_t at = 0;
};

namespace {

using Stream = ZipStream;

voidpf ZCALLBACK openStream(voidpf opaque, const void*, int) {
  static_cast<Stream*>(opaque)->at = 0;
  return opaque;
}
uLong ZCALLBACK readStream(voidpf, voidpf stream, void* buf, uLong size) {
  Stream& s = *static_cast<Stream*>(stream);
  if (!s.in || s.at >= s.in->size()) return 0;
  const uint64_t n = std::min<uint64_t>(size, s.in->size() - s.at);
  std::memcpy(buf, s.in->data() + s.at, size_t(n));
  s.at += n;
  return uLong(n);
}
uLong ZCALLBACK writeStream(voidpf, voidpf stream, const void* buf, uLong size) {
  Stream& s = *static_cast<Stream*>(stream);
  if (!s.out) return 0;
  // zip.c writes forward and seeks back to complete a local header: overwrite in place.
  if (s.at + size > s.out->size()) s.out->resize(size_t(s.at + size));
  std::memcpy(s.out->data() + s.at, buf, size);
  s.at += size;
  return size;
}
ZPOS64_T ZCALLBACK tellStream(voidpf, voidpf stream) { return static_cast<Stream*>(stream)->at; }
long ZCALLBACK seekStream(voidpf, voidpf stream, ZPOS64_T offset, int origin) {
  Stream& s = *static_cast<Stream*>(stream);
  const uint64_t size = s.in ? s.in->size() : s.out->size();
  uint64_t base = 0;
  switch (origin) {
    case ZLIB_FILEFUNC_SEEK_SET: base = 0; break;
    case ZLIB_FILEFUNC_SEEK_CUR: base = s.at; break;
    case ZLIB_FILEFUNC_SEEK_END: base = size; break;
    default: return -1;
  }
  if (offset > size || base > size - offset) return -1;  // never past the end
  s.at = base + offset;
  return 0;
}
int ZCALLBACK closeStream(voidpf, voidpf) { return 0; }
int ZCALLBACK errorStream(voidpf, voidpf) { return 0; }

zlib_filefunc64_def functions(Stream* s) {
  zlib_filefunc64_def f{};
  f.zopen64_file = openStream;
  f.zread_file = readStream;
  f.zwrite_file = writeStream;
  f.ztell64_file = tellStream;
  f.zseek64_file = seekStream;
  f.zclose_file = closeStream;
  f.zerror_file = errorStream;
  f.opaque = s;
  return f;
}

}  // namespace

ZipReader::ZipReader(const std::string& bytes, int maxEntries) : stream_(new ZipStream) {
  stream_->in = &bytes;
  zlib_filefunc64_def f = functions(stream_);
  zip_ = unzOpen2_64("memory", &f);
  if (!zip_) {
    delete stream_;
    throw Problem{"", "not a zip archive (no end of central directory, or it is damaged)"};
  }
  unz_global_info64 info{};
  if (unzGetGlobalInfo64(zip_, &info) != UNZ_OK || info.number_entry > uint64_t(maxEntries)) {
    const uint64_t n = info.number_entry;
    unzClose(zip_);
    delete stream_;
    throw Problem{"", fmt::format("the zip directory lists {} entries, more than {}", n, maxEntries)};
  }
}

ZipReader::~ZipReader() {
  unzClose(zip_);
  delete stream_;
}

bool ZipReader::has(const std::string& entry) {
  return unzLocateFile(zip_, entry.c_str(), 1) == UNZ_OK;
}

std::string ZipReader::read(const std::string& entry, uint64_t maxBytes) {
  if (unzLocateFile(zip_, entry.c_str(), 1) != UNZ_OK)
    throw Problem{entry, "no such entry in the archive"};
  unz_file_info64 info{};
  if (unzGetCurrentFileInfo64(zip_, &info, nullptr, 0, nullptr, 0, nullptr, 0) != UNZ_OK)
    throw Problem{entry, "cannot read the entry's directory record"};
  if (info.flag & 1) throw Problem{entry, "encrypted entries are not supported"};
  if (info.compression_method != 0 && info.compression_method != Z_DEFLATED)
    throw Problem{entry, fmt::format("compression method {} is not supported (only stored and deflate)",
                                     info.compression_method)};
  // Step 1: the declared size against the cap, before anything is allocated.
  if (info.uncompressed_size > maxBytes)
    throw Problem{entry, fmt::format("declares {} bytes decompressed, more than the limit of {}",
                                     info.uncompressed_size, maxBytes)};
  if (unzOpenCurrentFile(zip_) != UNZ_OK) throw Problem{entry, "cannot open the entry's data"};
  // Step 2: inflate piece by piece, checking the running total against the declared size (a
  // lying directory cannot make the output grow past it).
  // Reserved up to what the archive's bytes can inflate to (deflate expands at most 1032:1), so
  // that a small archive declaring a large entry allocates no more than its data makes.
  std::string out;
  out.reserve(size_t(std::min<uint64_t>(info.uncompressed_size,
                                        uint64_t(stream_->in->size()) * 1032 + 1024)));
  char piece[1 << 16];
  for (;;) {
    const int n = unzReadCurrentFile(zip_, piece, sizeof piece);
    if (n < 0) {
      unzCloseCurrentFile(zip_);
      throw Problem{entry, fmt::format("damaged compressed data (minizip error {})", n)};
    }
    if (n == 0) break;
    if (out.size() + size_t(n) > info.uncompressed_size) {
      unzCloseCurrentFile(zip_);
      throw Problem{entry, fmt::format("inflates to more than the {} bytes it declares",
                                       info.uncompressed_size)};
    }
    out.append(piece, size_t(n));
  }
  // Step 3: minizip checks the CRC when the whole entry has been read.
  const int closed = unzCloseCurrentFile(zip_);
  if (out.size() != info.uncompressed_size)
    throw Problem{entry, fmt::format("truncated: {} of the {} bytes it declares", out.size(),
                                     info.uncompressed_size)};
  if (closed == UNZ_CRCERROR) throw Problem{entry, "CRC-32 mismatch: the entry is damaged"};
  if (closed != UNZ_OK) throw Problem{entry, "cannot close the entry"};
  return out;
}

std::string writeZip(const std::vector<std::pair<std::string, std::string>>& entries) {
  std::string out;
  Stream s;
  s.out = &out;
  zlib_filefunc64_def f = functions(&s);
  zipFile zf = zipOpen2_64("memory", APPEND_STATUS_CREATE, nullptr, &f);
  if (!zf) throw Problem{"", "cannot start a zip archive"};
  for (const auto& [name, bytes] : entries) {
    zip_fileinfo info{};
    info.tmz_date.tm_year = 1980;  // a fixed time: identical entries make identical archives
    info.tmz_date.tm_mday = 1;
    const int large = bytes.size() >= 0xffffffffu ? 1 : 0;
    bool ok = zipOpenNewFileInZip64(zf, name.c_str(), &info, nullptr, 0, nullptr, 0, nullptr,
                                    Z_DEFLATED, Z_DEFAULT_COMPRESSION, large) == ZIP_OK;
    for (size_t at = 0; ok && at < bytes.size(); at += 1u << 30) {
      const size_t n = std::min<size_t>(bytes.size() - at, 1u << 30);
      ok = zipWriteInFileInZip(zf, bytes.data() + at, unsigned(n)) == ZIP_OK;
    }
    ok = zipCloseFileInZip(zf) == ZIP_OK && ok;
    if (!ok) {
      zipClose(zf, nullptr);
      throw Problem{name, "cannot write the entry"};
    }
  }
  if (zipClose(zf, nullptr) != ZIP_OK) throw Problem{"", "cannot finish the zip archive"};
  return out;
}

}  // namespace sv::display::detail
