// LibavOutput: one encoder feeding one muxer, writing to a temporary sibling of the output path
// that is renamed into place by Finish() (common/atomic_file.h). Shared by the MP4 and GIF
// writers. Not thread-safe: one thread drives it.
#pragma once

#include <memory>
#include <string>

#include "common/atomic_file.h"
#include "common/result.h"

struct AVCodecContext;
struct AVFormatContext;
struct AVFrame;
struct AVPacket;
struct AVStream;
struct AVDictionary;

namespace recruit::render {

// "av error text" for a libav return code.
std::string AvError(int code);
// The class of a libav error code (an errno one like EACCES or ENOSPC is I/O).
ErrorCode AvCode(int code);

class LibavOutput {
 public:
  ~LibavOutput();
  LibavOutput(const LibavOutput&) = delete;
  LibavOutput& operator=(const LibavOutput&) = delete;

  // Opens `path` (through its temporary sibling) with the named muxer ("mp4", "gif").
  static Result<std::unique_ptr<LibavOutput>> Open(const std::string& path, const char* muxer);

  AVFormatContext* format() { return format_; }
  // Call before OpenCodec when the muxer wants global headers (sets the codec flag).
  bool wants_global_header() const;
  // Opens the encoder `codec` (already configured) and adds its stream.
  Status AddStream(AVCodecContext* codec);
  // Writes the container header; `options` are muxer options (e.g. movflags=+faststart).
  Status WriteHeader(AVDictionary** options);
  // Sends a frame (nullptr flushes) and writes every packet it produces.
  Status Encode(AVFrame* frame);
  // Flushes the encoder, writes the trailer, closes the file and renames it into place.
  Status Finish();
  const std::string& path() const { return file_->path(); }

 private:
  LibavOutput() = default;

  std::unique_ptr<AtomicFile> file_;
  AVFormatContext* format_ = nullptr;
  AVCodecContext* codec_ = nullptr;  // not owned
  AVStream* stream_ = nullptr;
  AVPacket* packet_ = nullptr;
  bool header_written_ = false;
  bool finished_ = false;
};

}  // namespace recruit::render
