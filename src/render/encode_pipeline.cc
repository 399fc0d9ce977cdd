#include "render/encode_pipeline.h"

#include "render/png_still.h"

namespace recruit::render {

EncodePipeline::EncodePipeline(int width, int height, std::unique_ptr<Mp4Writer> mp4,
                               std::unique_ptr<GifWriter> gif, int gif_stride, int queue_frames)
    : mp4_(std::move(mp4)),
      gif_(std::move(gif)),
      gif_stride_(gif_stride < 1 ? 1 : gif_stride),
      async_(queue_frames > 0) {
  const int buffers = async_ ? queue_frames : 1;
  for (int i = 0; i < buffers; ++i) {
    storage_.push_back(std::make_unique<Frame>());
    storage_.back()->Resize(width, height);
    free_.push_back(storage_.back().get());
  }
  if (async_) thread_ = std::thread([this] { Run(); });
}

EncodePipeline::~EncodePipeline() {
  {
    std::lock_guard<std::mutex> lock(mu_);
    closing_ = true;
  }
  cv_.notify_all();
  if (thread_.joinable()) thread_.join();
}

Result<Frame*> EncodePipeline::Acquire() {
  std::unique_lock<std::mutex> lock(mu_);
  cv_.wait(lock, [this] { return !free_.empty() || !error_.ok(); });
  if (!error_.ok()) return Error{error_.error(), error_.code()};
  Frame* f = free_.back();
  free_.pop_back();
  f->still_path.clear();
  return f;
}

Status EncodePipeline::Submit(Frame* frame) {
  if (!async_) {
    Status s = Write(*frame);
    std::lock_guard<std::mutex> lock(mu_);
    free_.push_back(frame);
    if (!s.ok() && error_.ok()) error_ = s;
    return error_;
  }
  {
    std::lock_guard<std::mutex> lock(mu_);
    if (!error_.ok()) {
      free_.push_back(frame);
      return error_;
    }
    queue_.push_back(frame);
  }
  cv_.notify_all();
  return Status::Ok();
}

Status EncodePipeline::Write(const Frame& frame) {
  if (mp4_) {
    if (Status s = mp4_->Write(frame); !s.ok()) return s;
  }
  if (gif_ && frame.index % gif_stride_ == 0) {
    if (Status s = gif_->Write(frame); !s.ok()) return s;
  }
  if (!frame.still_path.empty()) {
    if (Status s = WritePngStill(frame, frame.still_path); !s.ok()) return s;
    std::lock_guard<std::mutex> lock(mu_);
    stills_.push_back(frame.still_path);
  }
  std::lock_guard<std::mutex> lock(mu_);
  ++encoded_;
  return Status::Ok();
}

void EncodePipeline::Run() {
  while (true) {
    Frame* frame = nullptr;
    bool failed = false;
    {
      std::unique_lock<std::mutex> lock(mu_);
      cv_.wait(lock, [this] { return !queue_.empty() || closing_; });
      if (queue_.empty()) return;  // closing and drained
      frame = queue_.front();
      queue_.pop_front();
      failed = !error_.ok();
    }
    Status s = failed ? Status::Ok() : Write(*frame);  // after an error, only drain
    {
      std::lock_guard<std::mutex> lock(mu_);
      if (!s.ok() && error_.ok()) error_ = s;
      free_.push_back(frame);
    }
    cv_.notify_all();
  }
}

void EncodePipeline::WaitIdle() {
  std::unique_lock<std::mutex> lock(mu_);
  cv_.wait(lock, [this] { return free_.size() == storage_.size(); });
}

Status EncodePipeline::Finish() {
  if (finished_) return error_;
  finished_ = true;
  {
    std::lock_guard<std::mutex> lock(mu_);
    closing_ = true;
  }
  cv_.notify_all();
  if (thread_.joinable()) thread_.join();
  if (!error_.ok()) return error_;
  if (mp4_) {
    if (Status s = mp4_->Finish(); !s.ok()) return error_ = s;
  }
  if (gif_) {
    if (Status s = gif_->Finish(); !s.ok()) return error_ = s;
  }
  return Status::Ok();
}

int64_t EncodePipeline::frames_encoded() const {
  std::lock_guard<std::mutex> lock(mu_);
  return encoded_;
}

std::vector<std::string> EncodePipeline::stills_written() const {
  std::lock_guard<std::mutex> lock(mu_);
  return stills_;
}

}  // namespace recruit::render
