// EncodePipeline: overlaps encoding with rendering. The render thread takes a free frame buffer
// (Acquire), fills it and hands it over (Submit); an encoder thread writes it to the MP4, every
// gif_stride-th frame to the GIF and requested stills to PNG, then returns the buffer. The pool
// of buffers is the bound on the queue: when the encoder falls behind, Acquire blocks, so
// memory stays at `queue_frames` frames. With queue_frames == 0 everything runs on the caller's
// thread (the benchmark's synchronous baseline).
#pragma once

#include <condition_variable>
#include <deque>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "common/result.h"
#include "render/frame.h"
#include "render/gif_writer.h"
#include "render/mp4_writer.h"

namespace recruit::render {

class EncodePipeline {
 public:
  // Any writer may be null (stills only, for example).
  EncodePipeline(int width, int height, std::unique_ptr<Mp4Writer> mp4,
                 std::unique_ptr<GifWriter> gif, int gif_stride, int queue_frames);
  ~EncodePipeline();  // stops the thread; unfinished files are removed by their writers
  EncodePipeline(const EncodePipeline&) = delete;
  EncodePipeline& operator=(const EncodePipeline&) = delete;

  // A free buffer sized width x height, or an error from the encoder thread.
  Result<Frame*> Acquire();
  // Queues the frame (from Acquire) for writing; returns an earlier encoder error, if any.
  Status Submit(Frame* frame);
  // Blocks until every submitted frame has been handed to the writers (benchmarks use it to
  // keep the encoder from running into a render-only measurement).
  void WaitIdle();
  // Writes what is queued, finishes every file (rename into place) and reports the first error.
  Status Finish();

  int64_t frames_encoded() const;
  std::vector<std::string> stills_written() const;

 private:
  void Run();
  Status Write(const Frame& frame);

  std::unique_ptr<Mp4Writer> mp4_;
  std::unique_ptr<GifWriter> gif_;
  const int gif_stride_;
  const bool async_;

  mutable std::mutex mu_;
  std::condition_variable cv_;
  std::vector<std::unique_ptr<Frame>> storage_;
  std::vector<Frame*> free_;
  std::deque<Frame*> queue_;
  bool closing_ = false;
  Status error_;
  int64_t encoded_ = 0;
  std::vector<std::string> stills_;
  std::thread thread_;
  bool finished_ = false;
};

}  // namespace recruit::render
