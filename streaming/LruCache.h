// A least-recently-used map under a byte budget, shared by the Streamer's caches. Entries are
// shared_ptr<const Value>, so a caller keeps what it found after eviction. Thread safe: every
// member takes the cache's mutex.
#pragma once

#include <cstddef>
#include <list>
#include <memory>
#include <mutex>
#include <optional>
#include <unordered_map>

namespace flipscope {

struct CacheStats {
  std::uint64_t hits = 0;
  std::uint64_t misses = 0;
  std::uint64_t evictions = 0;
  std::size_t entries = 0;
  std::size_t bytes = 0;
  double hitRate() const { return hits + misses ? double(hits) / double(hits + misses) : 0.0; }
};

template <class Key, class Value, class Hash>
class LruCache {
 public:
  explicit LruCache(std::size_t byteBudget) : mBudget(byteBudget) {}

  /// The entry (which may hold nullptr: a remembered absence), or nullopt on a miss.
  /// Counts a hit or a miss and marks the entry most recently used.
  std::optional<std::shared_ptr<const Value>> find(const Key& key) {
    std::lock_guard lock(mMutex);
    auto it = mMap.find(key);
    if (it == mMap.end()) {
      ++mStats.misses;
      return std::nullopt;
    }
    ++mStats.hits;
    mOrder.splice(mOrder.begin(), mOrder, it->second);
    return it->second->value;
  }

  /// Inserts or replaces; evicts least recently used entries until the total is within the
  /// budget. An entry larger than the budget is not kept.
  void insert(const Key& key, std::shared_ptr<const Value> value, std::size_t bytes) {
    std::lock_guard lock(mMutex);
    if (auto it = mMap.find(key); it != mMap.end()) {
      mBytes -= it->second->bytes;
      mOrder.erase(it->second);
      mMap.erase(it);
    }
    if (bytes > mBudget) return;
    while (mBytes + bytes > mBudget) {
      mBytes -= mOrder.back().bytes;
      mMap.erase(mOrder.back().key);
      mOrder.pop_back();
      ++mStats.evictions;
    }
    mOrder.push_front({key, std::move(value), bytes});
    mMap.emplace(key, mOrder.begin());
    mBytes += bytes;
  }

  bool contains(const Key& key) const {
    std::lock_guard lock(mMutex);
    return mMap.count(key) != 0;
  }
  std::size_t bytes() const {
    std::lock_guard lock(mMutex);
    return mBytes;
  }
  std::size_t budget() const { return mBudget; }
  /// Calls f(key) for every entry, under the cache's lock (f must not call the cache).
  template <class F>
  void forEachKey(F&& f) const {
    std::lock_guard lock(mMutex);
    for (const Entry& entry : mOrder) f(entry.key);
  }
  CacheStats stats() const {
    std::lock_guard lock(mMutex);
    CacheStats s = mStats;
    s.entries = mMap.size();
    s.bytes = mBytes;
    return s;
  }

 private:
  struct Entry {
    Key key;
    std::shared_ptr<const Value> value;
    std::size_t bytes;
  };
  const std::size_t mBudget;
  mutable std::mutex mMutex;
  std::list<Entry> mOrder;  ///< most recently used first
  std::unordered_map<Key, typename std::list<Entry>::iterator, Hash> mMap;
  std::size_t mBytes = 0;
  CacheStats mStats;
};

}  // namespace flipscope
