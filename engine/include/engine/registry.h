#pragma once
// The ECS registry: entities, one sparse-set storage per component type, multi-component
// views and per-frame change tracking.
//
//   engine::Registry reg;
//   engine::Entity e = reg.create();
//   reg.emplace<Transform>(e, Transform{.position = {0, 1, 0}});
//   reg.write<Transform>(e).position.x += 1;       // marks Transform of e changed this frame
//   reg.view<Transform, MeshRenderer>().each([](engine::Entity, const Transform&, const MeshRenderer&) {});
//   for (engine::Entity c : reg.changed<Transform>()) { ... }
//   reg.begin_frame();                             // clears the change sets
//
// Reads are const (`get`, `try_get`, views); the only mutable access is `write`/`emplace`,
// and both record a change, so "what changed this frame" is exact, never guessed.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

#include <engine/check.h>
#include <engine/entity.h>

namespace engine {

namespace detail {

inline std::size_t next_component_type_id() {
  static std::size_t counter = 0;
  return counter++;
}
template <class T>
std::size_t component_type_id() {
  static const std::size_t id = next_component_type_id();
  return id;
}

/// Type-erased part of a component storage, so the registry can remove an entity's
/// components and clear change sets without knowing their types.
class StorageBase {
 public:
  virtual ~StorageBase() = default;
  virtual bool contains(Entity e) const = 0;
  virtual void erase(Entity e) = 0;
  virtual void begin_frame() = 0;
  virtual std::size_t size() const = 0;
};

/// Sparse set: sparse[index] -> position in the dense arrays (entities, data).
template <class T>
class Storage final : public StorageBase {
 public:
  static constexpr std::uint32_t kAbsent = 0xffffffffu;

  bool contains(Entity e) const override {
    return e.index < sparse_.size() && sparse_[e.index] != kAbsent && entities_[sparse_[e.index]] == e;
  }
  std::size_t size() const override { return entities_.size(); }

  template <class... Args>
  T& emplace(Entity e, Args&&... args) {
    if (contains(e)) {
      T& slot = data_[sparse_[e.index]];
      if constexpr (sizeof...(Args) == 0) {
        slot = T{};
      } else {
        slot = T{std::forward<Args>(args)...};
      }
      mark(e);
      return slot;
    }
    if (e.index >= sparse_.size()) sparse_.resize(e.index + 1, kAbsent);
    sparse_[e.index] = static_cast<std::uint32_t>(entities_.size());
    entities_.push_back(e);
    if constexpr (sizeof...(Args) == 0) {
      data_.emplace_back();
    } else {
      data_.push_back(T{std::forward<Args>(args)...});
    }
    changed_frame_.push_back(kNever);
    mark(e);
    return data_.back();
  }

  void erase(Entity e) override {
    if (!contains(e)) return;
    const std::uint32_t pos = sparse_[e.index];
    const std::uint32_t last = static_cast<std::uint32_t>(entities_.size() - 1);
    if (pos != last) {
      entities_[pos] = entities_[last];
      data_[pos] = std::move(data_[last]);
      changed_frame_[pos] = changed_frame_[last];
      sparse_[entities_[pos].index] = pos;
    }
    entities_.pop_back();
    data_.pop_back();
    changed_frame_.pop_back();
    sparse_[e.index] = kAbsent;
    std::erase(changed_, e);
    removed_.push_back(e);
  }

  const T& get(Entity e) const {
    GI_EXPECTS(contains(e), "entity has no component of this type");
    return data_[sparse_[e.index]];
  }
  T& write(Entity e) {
    GI_EXPECTS(contains(e), "entity has no component of this type");
    mark(e);
    return data_[sparse_[e.index]];
  }
  const T* try_get(Entity e) const { return contains(e) ? &data_[sparse_[e.index]] : nullptr; }

  bool changed(Entity e) const { return contains(e) && changed_frame_[sparse_[e.index]] == frame_; }
  std::span<const Entity> changed_entities() const { return changed_; }
  std::span<const Entity> removed_entities() const { return removed_; }
  std::span<const Entity> entities() const { return entities_; }

  void begin_frame() override {
    ++frame_;
    changed_.clear();
    removed_.clear();
  }

 private:
  static constexpr std::uint64_t kNever = ~std::uint64_t{0};
  void mark(Entity e) {
    std::uint64_t& f = changed_frame_[sparse_[e.index]];
    if (f != frame_) {
      f = frame_;
      changed_.push_back(e);
    }
  }

  std::vector<std::uint32_t> sparse_;
  std::vector<Entity> entities_;
  std::vector<T> data_;
  std::vector<std::uint64_t> changed_frame_;
  std::vector<Entity> changed_;
  std::vector<Entity> removed_;
  std::uint64_t frame_ = 0;
};

}  // namespace detail

class Registry;

/// Entities holding every component in Ts. Iterates the smallest storage and filters by
/// the others; components are passed by const reference (use Registry::write to modify).
template <class... Ts>
class View {
 public:
  explicit View(const Registry& registry) : registry_(&registry) {}

  template <class F>
  void each(F&& f) const;

  /// The matching entities, in iteration order (a copy: safe to modify the registry while
  /// walking it).
  std::vector<Entity> entities() const;

 private:
  const Registry* registry_;
};

/// Owns entities and their components. Not thread-safe.
class Registry {
 public:
  Registry() = default;
  Registry(const Registry&) = delete;
  Registry& operator=(const Registry&) = delete;
  Registry(Registry&&) = default;
  Registry& operator=(Registry&&) = default;

  /// Creates an entity. Indices of destroyed entities are reused with a new generation.
  Entity create() {
    if (!free_.empty()) {
      const std::uint32_t index = free_.back();
      free_.pop_back();
      return Entity{index, generations_[index]};
    }
    GI_EXPECTS(generations_.size() < Entity::kNullIndex, "too many entities");
    generations_.push_back(0);
    return Entity{static_cast<std::uint32_t>(generations_.size() - 1), 0};
  }

  /// Destroys an entity and all its components; the handle becomes invalid forever.
  void destroy(Entity e) {
    GI_EXPECTS(valid(e), "destroy() of an invalid entity");
    for (auto& s : storages_)
      if (s) s->erase(e);
    ++generations_[e.index];
    free_.push_back(e.index);
    destroyed_.push_back(e);
  }

  /// True when e was created by this registry and not destroyed since.
  bool valid(Entity e) const { return e.index < generations_.size() && generations_[e.index] == e.generation; }

  /// Number of live entities.
  std::size_t alive() const { return generations_.size() - free_.size(); }

  /// Adds (or replaces) component T of e; records a change.
  template <class T, class... Args>
  T& emplace(Entity e, Args&&... args) {
    GI_EXPECTS(valid(e), "emplace() on an invalid entity");
    return storage<T>().emplace(e, std::forward<Args>(args)...);
  }

  /// Removes component T of e (no-op when absent); reported by removed<T>() this frame.
  template <class T>
  void remove(Entity e) {
    GI_EXPECTS(valid(e), "remove() on an invalid entity");
    if (has<T>(e)) storage<T>().erase(e);
  }

  template <class T>
  bool has(Entity e) const {
    const auto* s = find<T>();
    return s && s->contains(e);
  }

  /// Read access; e must have T.
  template <class T>
  const T& get(Entity e) const {
    const auto* s = find<T>();
    GI_EXPECTS(s != nullptr, "get() of a component type no entity has");
    return s->get(e);
  }

  /// Read access, or nullptr when e has no T.
  template <class T>
  const T* try_get(Entity e) const {
    const auto* s = find<T>();
    return s ? s->try_get(e) : nullptr;
  }

  /// Write access; e must have T. Marks T of e changed for this frame.
  template <class T>
  T& write(Entity e) {
    GI_EXPECTS(has<T>(e), "write() of a component the entity does not have");
    return storage<T>().write(e);
  }

  /// True when T of e was emplaced or written since the last begin_frame().
  template <class T>
  bool changed(Entity e) const {
    const auto* s = find<T>();
    return s && s->changed(e);
  }

  /// Entities whose T was emplaced or written since the last begin_frame(), in order of
  /// their first change.
  template <class T>
  std::span<const Entity> changed() const {
    const auto* s = find<T>();
    return s ? s->changed_entities() : std::span<const Entity>{};
  }

  /// Entities that lost T (remove or destroy) since the last begin_frame().
  template <class T>
  std::span<const Entity> removed() const {
    const auto* s = find<T>();
    return s ? s->removed_entities() : std::span<const Entity>{};
  }

  /// Entities destroyed since the last begin_frame().
  std::span<const Entity> destroyed() const { return destroyed_; }

  /// All entities that have T, in storage order.
  template <class T>
  std::span<const Entity> entities_with() const {
    const auto* s = find<T>();
    return s ? s->entities() : std::span<const Entity>{};
  }

  template <class... Ts>
  View<Ts...> view() const {
    return View<Ts...>(*this);
  }

  /// Starts a new frame: clears every change, removal and destruction record.
  void begin_frame() {
    ++frame_;
    for (auto& s : storages_)
      if (s) s->begin_frame();
    destroyed_.clear();
  }

  /// Number of begin_frame() calls so far.
  std::uint64_t frame() const { return frame_; }

  template <class T>
  const detail::Storage<T>* find() const {
    const std::size_t id = detail::component_type_id<T>();
    return id < storages_.size() ? static_cast<const detail::Storage<T>*>(storages_[id].get()) : nullptr;
  }

 private:
  template <class T>
  detail::Storage<T>& storage() {
    const std::size_t id = detail::component_type_id<T>();
    if (id >= storages_.size()) storages_.resize(id + 1);
    if (!storages_[id]) storages_[id] = std::make_unique<detail::Storage<T>>();
    return *static_cast<detail::Storage<T>*>(storages_[id].get());
  }

  std::vector<std::uint32_t> generations_;
  std::vector<std::uint32_t> free_;
  std::vector<std::unique_ptr<detail::StorageBase>> storages_;
  std::vector<Entity> destroyed_;
  std::uint64_t frame_ = 0;
};

template <class... Ts>
template <class F>
void View<Ts...>::each(F&& f) const {
  for (Entity e : entities()) f(e, registry_->get<Ts>(e)...);
}

template <class... Ts>
std::vector<Entity> View<Ts...>::entities() const {
  std::span<const Entity> smallest;
  bool any_missing = false;
  bool first = true;
  auto pick = [&]<class T>() {
    const auto* s = registry_->find<T>();
    if (!s) {
      any_missing = true;
      return;
    }
    if (first || s->entities().size() < smallest.size()) smallest = s->entities();
    first = false;
  };
  (pick.template operator()<Ts>(), ...);
  std::vector<Entity> out;
  if (any_missing) return out;
  out.reserve(smallest.size());
  for (Entity e : smallest)
    if ((registry_->has<Ts>(e) && ...)) out.push_back(e);
  return out;
}

}  // namespace engine
