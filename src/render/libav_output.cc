#include "render/libav_output.h"

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/error.h>
#include <libavutil/log.h>
}

#include <mutex>

namespace recruit::render {

ErrorCode AvCode(int code) {
  return CodeOf(std::error_code(AVUNERROR(code), std::generic_category()));
}

std::string AvError(int code) {
  char buf[AV_ERROR_MAX_STRING_SIZE] = {0};
  av_strerror(code, buf, sizeof(buf));
  return buf;
}

LibavOutput::~LibavOutput() {
  if (format_) {
    if (format_->pb) avio_closep(&format_->pb);
    avformat_free_context(format_);
  }
  av_packet_free(&packet_);
  // file_ (destroyed after this body) removes the temporary file unless Finish() committed it.
}

Result<std::unique_ptr<LibavOutput>> LibavOutput::Open(const std::string& path, const char* muxer) {
  // libav's default (info) level prints x264's statistics for every file; keep warnings and
  // errors unless the host program chose a level itself.
  static std::once_flag quiet;
  std::call_once(quiet, [] {
    if (av_log_get_level() == AV_LOG_INFO) av_log_set_level(AV_LOG_WARNING);
  });
  std::unique_ptr<LibavOutput> out(new LibavOutput());
  // Creating the AtomicFile checks the directory is writable and reserves the temporary name.
  out->file_ = std::make_unique<AtomicFile>(path, std::ios::binary);
  if (!out->file_->ok()) return Error{out->file_->error(), out->file_->code()};
  const std::string& tmp = out->file_->temp_path();
  int err = avformat_alloc_output_context2(&out->format_, nullptr, muxer, tmp.c_str());
  if (err < 0 || !out->format_) {
    return Error{"'" + path + "': libavformat has no '" + muxer + "' muxer (" + AvError(err) + ")",
                 AvCode(err)};
  }
  // The muxer writes (and, for MP4 faststart, re-reads) the temporary file by name.
  err = avio_open(&out->format_->pb, tmp.c_str(), AVIO_FLAG_WRITE);
  if (err < 0) return Error{"cannot write '" + path + "': " + AvError(err), ErrorCode::kIo};
  out->packet_ = av_packet_alloc();
  if (!out->packet_) return Error{"out of memory"};
  return out;
}

bool LibavOutput::wants_global_header() const {
  return format_->oformat->flags & AVFMT_GLOBALHEADER;
}

Status LibavOutput::AddStream(AVCodecContext* codec) {
  codec_ = codec;
  stream_ = avformat_new_stream(format_, nullptr);
  if (!stream_) return Error{"'" + path() + "': cannot add a stream"};
  const int err = avcodec_parameters_from_context(stream_->codecpar, codec);
  if (err < 0) return Error{"'" + path() + "': " + AvError(err), AvCode(err)};
  stream_->time_base = codec->time_base;
  stream_->avg_frame_rate = codec->framerate;
  return Status::Ok();
}

Status LibavOutput::WriteHeader(AVDictionary** options) {
  const int err = avformat_write_header(format_, options);
  if (err < 0)
    return Error{"'" + path() + "': cannot write the header: " + AvError(err), ErrorCode::kIo};
  header_written_ = true;
  return Status::Ok();
}

Status LibavOutput::Encode(AVFrame* frame) {
  int err = avcodec_send_frame(codec_, frame);
  if (err < 0)
    return Error{"'" + path() + "': encoder rejected a frame: " + AvError(err), AvCode(err)};
  while (true) {
    err = avcodec_receive_packet(codec_, packet_);
    if (err == AVERROR(EAGAIN) || err == AVERROR_EOF) return Status::Ok();
    if (err < 0) return Error{"'" + path() + "': encoding failed: " + AvError(err), AvCode(err)};
    av_packet_rescale_ts(packet_, codec_->time_base, stream_->time_base);
    packet_->stream_index = stream_->index;
    err = av_interleaved_write_frame(format_, packet_);
    if (err < 0) return Error{"cannot write '" + path() + "': " + AvError(err), ErrorCode::kIo};
  }
}

Status LibavOutput::Finish() {
  if (finished_) return Status::Ok();
  if (!header_written_) return Error{"'" + path() + "': nothing was written"};
  if (Status s = Encode(nullptr); !s.ok()) return s;
  int err = av_write_trailer(format_);
  if (err < 0) return Error{"cannot finish '" + path() + "': " + AvError(err), AvCode(err)};
  err = avio_closep(&format_->pb);
  if (err < 0) return Error{"cannot close '" + path() + "': " + AvError(err), AvCode(err)};
  finished_ = true;
  return file_->Commit();
}

}  // namespace recruit::render
