// Subscriptions whose messages are deserialised with every array length checked first (issue 42).
// roscpp sizes each array of a message from its 4-byte length prefix before it reads the elements:
// a 550-byte PlacedScan whose codes array claims 1e8 entries makes the receiver allocate (and zero)
// 200 MB, 2^32 - 1 entries of float32 16 GiB, before the read fails. Here a prefix is compared
// with the bytes left in the message first: an array whose elements cannot all be there (each at
// least its smallest serialised size) is refused before anything is allocated, and so is a
// message shorter than its fields; the subscriber is told (counted, warned) and its callback never
// sees the message. Everything else is deserialised exactly as roscpp does. The topic's type,
// md5sum and definition are the message's own: publishers see an ordinary subscriber.
// ros::serialization's Serializer specialisations are global, so the check lives in a stream type
// of its own (CheckedIStream) and a callback helper (CheckedCallbackHelper) of this subscription
// only. A plain subscriber of the same topic and type in the same process may share roscpp's
// deserialised message with it (roscpp deserialises once per type and connection).
#ifndef WAVOG_MAPPING_SRC_ROS_CHECKED_SUBSCRIPTION_H_
#define WAVOG_MAPPING_SRC_ROS_CHECKED_SUBSCRIPTION_H_

#include <ros/ros.h>
#include <ros/serialization.h>
#include <ros/subscription_callback_helper.h>

#include <algorithm>
#include <boost/make_shared.hpp>
#include <cstdint>
#include <cstring>
#include <functional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace wavog_ros {

/// An array length prefix that claims more elements than the bytes left can hold.
class ArrayLengthRefused : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The fewest bytes one element of type T takes in a message: its fixed fields, and a 4-byte
/// length for each string and array in it (a default-constructed T). At least 1, so that even an
/// array of empty messages is bounded by the bytes of the message.
template <typename T>
std::uint32_t minSerializedSize() {
  static const std::uint32_t size =
      std::max<std::uint32_t>(1, ros::serialization::serializationLength(T()));
  return size;
}

/// ros::serialization's input stream with one difference: before an array is sized from its
/// length prefix, the prefix is checked against the bytes left (ArrayLengthRefused). Reads past
/// the end throw ros::serialization::StreamOverrunException, as IStream's do.
class CheckedIStream : public ros::serialization::Stream {
 public:
  static const ros::serialization::StreamType stream_type = ros::serialization::stream_types::Input;

  CheckedIStream(std::uint8_t* data, std::uint32_t count)
      : Stream(data, count), start_(data), read_(data) {}

  template <typename T>
  void next(T& t) {
    ros::serialization::deserialize(*this, t);
    read_ = getData();
  }

  /// Bytes of the fields read completely so far (the fields before a refusal).
  std::uint32_t bytesRead() const { return static_cast<std::uint32_t>(read_ - start_); }

  template <typename T, typename A>
  void next(std::vector<T, A>& v) {
    constexpr std::uint32_t kPrefix = 4;
    if (getLength() >= kPrefix) {  // else the prefix's own read throws StreamOverrunException
      std::uint32_t n = 0;
      std::memcpy(&n, getData(), kPrefix);
      const std::uint64_t left = getLength() - kPrefix;
      const std::uint64_t element = minSerializedSize<T>();
      if (static_cast<std::uint64_t>(n) * element > left) {
        throw ArrayLengthRefused("an array claims " + std::to_string(n) + " elements of at least " +
                                 std::to_string(element) + " bytes, but " + std::to_string(left) +
                                 " bytes are left in the message");
      }
    }
    ros::serialization::deserialize(*this, v);
    read_ = getData();
  }

 private:
  std::uint8_t* start_;
  std::uint8_t* read_;  ///< the end of the last field read completely
};

/// Deserialises `length` bytes at `data` into *msg through CheckedIStream. Returns false, with
/// the reason in *why, for an array longer than its bytes or a message shorter than its fields;
/// *msg then holds the fields read before the refusal (e.g. the header of a LaserScan), the first
/// *bytes_read bytes of the message (when bytes_read is not null).
template <typename M>
bool checkedDeserialize(std::uint8_t* data, std::uint32_t length, M* msg, std::string* why,
                        std::uint32_t* bytes_read = nullptr) {
  CheckedIStream stream(data, length);
  try {
    ros::serialization::Serializer<M>::read(stream, *msg);
    if (bytes_read != nullptr) *bytes_read = stream.bytesRead();
    return true;
  } catch (const ArrayLengthRefused& e) {
    *why = e.what();
  } catch (const ros::serialization::StreamOverrunException&) {
    *why = "the message (" + std::to_string(length) + " bytes) ends inside its fields";
  }
  if (bytes_read != nullptr) *bytes_read = stream.bytesRead();
  return false;
}

/// What a subscriber hears about a refused message: the fields read before the refusal (its
/// first `bytes_read` bytes), why, the message's length, and an opaque id of the connection it
/// came through (the address of roscpp's connection header, as
/// ros::MessageEvent::getConnectionHeaderPtr() gives it).
struct Refused {
  std::string why;
  std::uint32_t bytes_read = 0;
  std::uint32_t length = 0;
  std::uintptr_t connection = 0;
};
template <typename M>
using RefusalCallback = std::function<void(const M& partial, const Refused& refused)>;

/// roscpp's callback helper for `const ros::MessageEvent<M const>&` callbacks, deserialising
/// through checkedDeserialize(): a refused message goes to `refused` and never to the callback
/// (roscpp skips a message its helper returns null for).
template <typename M>
class CheckedCallbackHelper
    : public ros::SubscriptionCallbackHelperT<const ros::MessageEvent<M const>&> {
 public:
  using Base = ros::SubscriptionCallbackHelperT<const ros::MessageEvent<M const>&>;

  CheckedCallbackHelper(const typename Base::Callback& callback, RefusalCallback<M> refused)
      : Base(callback), refused_(std::move(refused)) {}

  ros::VoidConstPtr deserialize(
      const ros::SubscriptionCallbackHelperDeserializeParams& params) override {
    auto msg = boost::make_shared<M>();
    ros::serialization::PreDeserializeParams<M> pre;
    pre.message = msg;
    pre.connection_header = params.connection_header;
    ros::serialization::PreDeserialize<M>::notify(pre);
    Refused r;
    if (!checkedDeserialize(params.buffer, params.length, msg.get(), &r.why, &r.bytes_read)) {
      r.length = params.length;
      r.connection = reinterpret_cast<std::uintptr_t>(params.connection_header.get());
      refused_(*msg, r);
      return ros::VoidConstPtr();
    }
    return msg;
  }

 private:
  RefusalCallback<M> refused_;
};

/// Subscribes `callback` to `topic` (type M, TCP_NODELAY) with checked deserialisation:
/// messages refused by checkedDeserialize() go to `refused` instead.
template <typename M>
ros::Subscriber subscribeChecked(
    ros::NodeHandle& nh, const std::string& topic, std::uint32_t queue_size,
    const boost::function<void(const ros::MessageEvent<M const>&)>& callback,
    RefusalCallback<M> refused) {
  ros::SubscribeOptions ops;
  ops.template initByFullCallbackType<const ros::MessageEvent<M const>&>(topic, queue_size,
                                                                         callback);
  ops.helper = boost::make_shared<CheckedCallbackHelper<M>>(callback, std::move(refused));
  ops.transport_hints = ros::TransportHints().tcpNoDelay();
  return nh.subscribe(ops);
}

}  // namespace wavog_ros

#endif  // WAVOG_MAPPING_SRC_ROS_CHECKED_SUBSCRIPTION_H_
