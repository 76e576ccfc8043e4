#pragma once

namespace pspslam {

// Lowers the scheduling priority of the calling thread only (Linux: the nice value of this
// thread's id; other threads of the process keep theirs). Real-time runs use it so that the
// network, local mapping and loop closing yield a core to the caller thread, which must track
// each frame before the next arrives (issue #18). `increment` <= 0 changes nothing. Returns
// false when the system refused (then the thread runs on at its old priority).
bool lower_this_thread_priority(int increment);

// The calling thread's nice value (for tests and the run report).
int this_thread_nice();

}  // namespace pspslam
