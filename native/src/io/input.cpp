// Input and ByteStream: the bytes that readers read, from memory or a file.
#include <sys/stat.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

#include "io/io_internal.h"

namespace kdmesh::io::detail {
namespace {

// Reads up to `count` bytes at the file's position into `into`; returns how
// many arrived, setting `readError` to errno if a read failed.
size_t readUpTo(std::FILE* file, uint8_t* into, size_t count, int& readError) {
  const size_t got = std::fread(into, 1, count, file);
  if (got < count && std::ferror(file) && readError == 0) {
    readError = errno != 0 ? errno : EIO;
  }
  return got;
}

bool seekTo(std::FILE* file, uint64_t offset, int& readError) {
  if (fseeko(file, static_cast<off_t>(offset), SEEK_SET) == 0) return true;
  if (readError == 0) readError = errno != 0 ? errno : EIO;
  return false;
}

}  // namespace

Status fileError(const char* action, const std::string& path, int error) {
  return Status::error(ErrorCode::InvalidArgument, std::string(action) + " " +
                                                       path + ": " +
                                                       std::strerror(error));
}

// ---------------------------------------------------------------------------
// ByteStream
// ---------------------------------------------------------------------------

ByteStream::ByteStream(const uint8_t* data, size_t size, uint64_t offset)
    : window_(data),
      cursor_(data),
      limit_(data + size),
      windowOffset_(offset),
      end_(offset + size) {}

ByteStream::ByteStream(std::FILE* file, uint64_t offset, uint64_t end,
                       int* readError)
    : file_(file),
      readError_(readError),
      window_(nullptr),
      cursor_(nullptr),
      limit_(nullptr),
      windowOffset_(offset),
      end_(std::max(offset, end)) {
  if (!seekTo(file_, offset, *readError_)) end_ = offset;
}

const uint8_t* ByteStream::take(size_t count) {
  if (static_cast<size_t>(limit_ - cursor_) < count && !refill(count)) {
    return nullptr;
  }
  const uint8_t* bytes = cursor_;
  cursor_ += count;
  return bytes;
}

bool ByteStream::skip(uint64_t count) {
  if (count > remaining()) return false;
  if (count <= static_cast<uint64_t>(limit_ - cursor_)) {
    cursor_ += count;
    return true;
  }
  // Only a file holds fewer bytes than remain: drop its block and seek.
  const uint64_t target = offset() + count;
  window_ = cursor_ = limit_ = buffer_.data();
  windowOffset_ = target;
  if (!seekTo(file_, target, *readError_)) end_ = target;
  return true;
}

// Keeps the unread bytes of the block and reads the file on after them.
bool ByteStream::refill(size_t count) {
  if (file_ == nullptr || count > kBlockBytes) return false;
  if (buffer_.empty()) buffer_.resize(kBlockBytes);
  const size_t kept = static_cast<size_t>(limit_ - cursor_);
  windowOffset_ = offset();
  if (kept > 0) std::memmove(buffer_.data(), cursor_, kept);
  const uint64_t unread = end_ - windowOffset_ - kept;
  const size_t wanted =
      static_cast<size_t>(std::min<uint64_t>(kBlockBytes - kept, unread));
  const size_t got =
      readUpTo(file_, buffer_.data() + kept, wanted, *readError_);
  if (got < wanted) end_ = windowOffset_ + kept + got;  // shorter than stated
  window_ = cursor_ = buffer_.data();
  limit_ = window_ + kept + got;
  return kept + got >= count;
}

// ---------------------------------------------------------------------------
// Input
// ---------------------------------------------------------------------------

Input::Input(const uint8_t* data, size_t size)
    : sized_(true), size_(size), whole_{data, size}, haveWhole_(true) {}

Status Input::open(const std::string& path, Input& input, bool* missing) {
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (file == nullptr) {
    if (missing) *missing = errno == ENOENT;
    return fileError("cannot open", path, errno);
  }
  input.file_.reset(file);
  input.path_ = path;
  // Pipes and devices have no size, and some files (those of /proc) report
  // none: those are read to their end when a reader needs all of them.
  struct stat info;
  if (fstat(fileno(file), &info) == 0 && S_ISREG(info.st_mode) &&
      info.st_size > 0) {
    input.sized_ = true;
    input.size_ = static_cast<uint64_t>(info.st_size);
  }
  return Status::success();
}

Bytes Input::head() {
  if (haveWhole_) return {whole_.data, std::min(whole_.size, kHeadBytes)};
  if (!haveHead_) {
    haveHead_ = true;
    // A file that is not regular cannot seek, but is read from its start.
    head_.resize(sized_ ? std::min<uint64_t>(size_, kHeadBytes) : kHeadBytes);
    const bool atStart = !sized_ || seekTo(file_.get(), 0, readError_);
    head_.resize(atStart ? readUpTo(file_.get(), head_.data(), head_.size(),
                                    readError_)
                         : 0);
  }
  return {head_.data(), head_.size()};
}

bool Input::headIsWhole() {
  const size_t held = head().size;
  if (haveWhole_) return held == whole_.size;
  return held < kHeadBytes || (sized_ && size_ <= kHeadBytes);
}

Bytes Input::whole() {
  if (haveWhole_) return whole_;
  if (sized_) {
    // One allocation of the stated size: no copy as the buffer grows.
    all_.resize(static_cast<size_t>(size_));
    size_t got = 0;
    if (seekTo(file_.get(), 0, readError_)) {
      got = readUpTo(file_.get(), all_.data(), all_.size(), readError_);
    }
    all_.resize(got);
  } else {
    // The head was the first block; the rest arrives in growing blocks.
    head();
    all_ = head_;
    for (size_t block = kHeadBytes; readError_ == 0 && !std::feof(file_.get());
         block = std::min<size_t>(2 * block, size_t{1} << 26)) {
      const size_t used = all_.size();
      all_.resize(used + block);
      all_.resize(used + readUpTo(file_.get(), all_.data() + used, block,
                                  readError_));
    }
  }
  whole_ = {all_.data(), all_.size()};
  haveWhole_ = true;
  sized_ = true;
  size_ = whole_.size;
  return whole_;
}

uint64_t Input::size() { return sized_ ? size_ : whole().size; }

ByteStream Input::stream(uint64_t offset) {
  if (!haveWhole_ && sized_) {
    return ByteStream(file_.get(), offset, size_, &readError_);
  }
  const Bytes all = whole();
  const size_t start =
      static_cast<size_t>(std::min<uint64_t>(offset, all.size));
  return ByteStream(all.data + start, all.size - start, start);
}

Status Input::readError() const {
  if (readError_ == 0) return Status::success();
  return fileError("cannot read", path_, readError_);
}

}  // namespace kdmesh::io::detail
