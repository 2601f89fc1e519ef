// The generated DDS type supports under the names the code uses: mft::msg::<Name>PubSubType for
// mft::msg::dds_::<Name>_PubSubType (idl/msg_types.hpp), and PubSubOf<M>::type for a message type M.
#pragma once

#include "idl/msg_types.hpp"
#include "mft_msgsPubSubTypes.h"

#include <fastcdr/exceptions/Exception.h>

namespace mft::msg {
// fastddsgen's deserialize() catches only a short buffer: fastcdr's BadParamException (an encapsulation byte it does
// not know, a boolean byte other than 0 or 1) escapes it, and a DDS reader or chain-channel slot given such bytes by
// a writer outside the stack ended the process (found by fuzz/fuzz_dds_sample.cpp). Such bytes are refused here like
// a short sample: deserialize() returns false.
template <class Generated>
class CheckedPubSubType : public Generated {
 public:
  bool deserialize(eprosima::fastrtps::rtps::SerializedPayload_t* payload, void* data) override {
    try {
      return Generated::deserialize(payload, data);
    } catch (const eprosima::fastcdr::exception::Exception&) {
      return false;
    }
  }
};
template <class M>
struct PubSubOf;
#define MFT_MSG_PUBSUB_ALIAS(Name)   \
  using Name##PubSubType = CheckedPubSubType<dds_::Name##_PubSubType>; \
  template <>                        \
  struct PubSubOf<Name> {            \
    using type = Name##PubSubType;   \
  };
MFT_MSG_TYPES(MFT_MSG_PUBSUB_ALIAS)
#undef MFT_MSG_PUBSUB_ALIAS
}  // namespace mft::msg
