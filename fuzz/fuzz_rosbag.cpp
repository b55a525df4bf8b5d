// libFuzzer target: the ROS bag reader on an in-memory rosbag file (see fuzz_bag.hpp).
#include "fuzz_bag.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    return evcorner::fuzz::run_bag(data, size, "rosbag");
}
