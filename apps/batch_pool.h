#pragma once
/// \file batch_pool.h
/// segment-batch's worker processes: each image of a batch segmented in a process forked
/// from the batch (after the model is read), its row of batch.json sent back on a pipe.
/// Processes and not threads: a segmentation forks to render its page, which a second thread
/// holding a lock would deadlock, and ITK's thread settings are global.
#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace mrsnake::cli {

/// The row of batch.json of image `index`, computed in a worker; failures are recorded in
/// the row, not thrown.
using BatchRowFn = std::function<nlohmann::json(std::size_t index)>;

/// Runs row(i) for every image in `jobs` worker processes (worker w takes images w,
/// w + jobs, ...), calling `done(index, row)` in this process as rows come in, with the row's
/// "image" and "output" set to images[index] and outputs[index] as given. A worker that
/// stops (a crash, a kill) leaves its remaining images with a "failed" row that says so.
/// \pre jobs >= 2; images.size() == outputs.size(); this process runs no other thread.
/// \throw Error if a worker cannot be started or its pipe fails.
void run_batch_in_processes(int jobs, const std::vector<std::string>& images, const std::vector<std::string>& outputs,
                            const BatchRowFn& row, const std::function<void(std::size_t, nlohmann::json)>& done);

}  // namespace mrsnake::cli
