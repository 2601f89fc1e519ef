// The generated DDS type supports under the names the code uses: mft::msg::<Name>PubSubType for
// mft::msg::dds_::<Name>_PubSubType (idl/msg_types.hpp), and PubSubOf<M>::type for a message type M.
#pragma once

#include "idl/msg_types.hpp"
#include "mft_msgsPubSubTypes.h"

namespace mft::msg {
template <class M>
struct PubSubOf;
#define MFT_MSG_PUBSUB_ALIAS(Name)   \
  using Name##PubSubType = dds_::Name##_PubSubType; \
  template <>                        \
  struct PubSubOf<Name> {            \
    using type = Name##PubSubType;   \
  };
MFT_MSG_TYPES(MFT_MSG_PUBSUB_ALIAS)
#undef MFT_MSG_PUBSUB_ALIAS
}  // namespace mft::msg
