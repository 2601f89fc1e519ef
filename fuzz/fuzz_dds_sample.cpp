// Fuzz target: a sample from a DDS writer outside the stack (mft-inject, a foreign controller, a ROS 2 node) or a
// chain-channel slot, as the stack's readers take it. The input's first byte picks the topic (modulo the number of
// topics, in the registry's order), the rest is the serialized sample (encapsulation + CDR). The bytes are decoded
// the way every reader decodes them (services/runtime/topic_io.hpp), then go through the checks the reading
// services make on arrival (msg_guard, the actuator driver, the disturbance and operator-command checks, the live
// tuning judge) and, for a recorded topic, through mft-record's encoding and back. Accepted: the stack would act on
// the sample; refused: undecodable, or refused by a check, with the reason.
#include <type_traits>

#include "fuzz/dds_arrival.hpp"
#include "fuzz/fuzz_target.hpp"
#include "idl/msg_pubsub.hpp"
#include "services/runtime/topic_io.hpp"

namespace mft::fuzz {

namespace {

// The recorder's view of the sample: encoded into its observations and reassembled; the tick (or seq) must come
// back exactly, the stamp to the 100 ns of an MRPT timestamp.
template <class M>
void recordAndReadBack(const M& sample) {
  if constexpr (std::is_constructible_v<rawlog::Message, M> && !std::is_same_v<M, msg::RecorderProgress>) {
    static rawlog::ObservationEncoder encoder;
    const rawlog::Message m = sample;
    const auto unix_ns = static_cast<std::int64_t>(rawlog::stampOf(m));
    rawlog::MessageAssembler assembler(0);
    rawlog::Message back;
    std::int64_t back_ns = 0;
    bool complete = false;
    for (int label : encoder.encode(m, unix_ns)) complete = assembler.add(encoder.observation(label), &back, &back_ns);
    const auto stamp_back = static_cast<std::uint64_t>(unix_ns / 100 * 100);
    if (!complete || rawlog::tickOf(back) != rawlog::tickOf(m) || rawlog::stampOf(back) != stamp_back)
      throw std::logic_error("a recorded sample does not read back with its tick and stamp");
  }
}

template <class M>
Outcome take(const std::uint8_t* bytes, std::size_t size) {
  using PubSubType = typename msg::PubSubOf<M>::type;
  static PubSubType type;
  static eprosima::fastrtps::rtps::SerializedPayload_t payload(type.m_typeSize);
  static M sample;
  const std::string origin = "a " + std::string(msg::topicInfo<M>().type) + " sample";
  if (!services::fromChainBytes(type, payload, bytes, size, &sample))
    return refusedWith(origin + " that does not decode (" + std::to_string(size) + " bytes)", origin);
  recordAndReadBack(sample);
  const std::string why = arrivalCheck(sample);
  if (!why.empty()) return refusedWith(origin + " refused on arrival: " + why, origin);
  return acceptedAs(origin + " the stack takes");
}

}  // namespace

Outcome runOne(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return refusedWith("an empty input names no topic", "input");
  const std::size_t topic = data[0] % msg::kTopics.size();
  Outcome outcome;
  std::size_t index = 0;
  msg::forEachTopicType([&](auto tag) {
    if (index++ == topic) outcome = take<typename decltype(tag)::type>(data + 1, size - 1);
  });
  return outcome;
}

}  // namespace mft::fuzz
