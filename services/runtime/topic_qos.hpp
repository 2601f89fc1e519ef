#pragma once
// The QoS profile (config/dds_profiles.xml) of a service's endpoint on a topic, from the topic's qos class in the
// registry (idl/topics.yaml), so that no service names a profile by hand:
//   chain     lockstep_writer / lockstep_reader in lockstep (every tick must arrive), control_writer /
//             control_reader in realtime (best effort, deadline-watched);
//   event     verdict_writer (a service writes an event topic only to answer: CommandVerdict, an applied
//             ConfigChange) / event_reader;
//   progress  lockstep_writer / lockstep_reader (flow control: re-sent, the newest counts).
// Tools that write requests (command_writer, event_writer) name their own.
#include <string>
#include <string_view>

namespace mft::services {

// Throw DdsError for a topic the registry does not list.
std::string serviceWriterProfile(std::string_view topic, bool lockstep);
std::string serviceReaderProfile(std::string_view topic, bool lockstep);

}  // namespace mft::services
