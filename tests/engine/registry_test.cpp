#include <engine/components.h>
#include <engine/registry.h>

#include <gtest/gtest.h>

namespace {

struct Health {
  int hp = 100;
};

TEST(Registry, DestroyedIdNeverAliasesNewEntity) {
  engine::Registry reg;
  const engine::Entity a = reg.create();
  reg.destroy(a);
  const engine::Entity b = reg.create();
  EXPECT_EQ(a.index, b.index);  // the slot is reused...
  EXPECT_NE(a, b);              // ...with a new generation
  EXPECT_FALSE(reg.valid(a));
  EXPECT_TRUE(reg.valid(b));
  EXPECT_FALSE(reg.has<Health>(b));
}

TEST(Registry, DestroyRemovesComponentsAndReportsThem) {
  engine::Registry reg;
  const engine::Entity a = reg.create();
  reg.emplace<Health>(a, Health{5});
  reg.begin_frame();
  reg.destroy(a);
  ASSERT_EQ(reg.removed<Health>().size(), 1u);
  EXPECT_EQ(reg.removed<Health>()[0], a);
  ASSERT_EQ(reg.destroyed().size(), 1u);
  EXPECT_EQ(reg.entities_with<Health>().size(), 0u);
  reg.begin_frame();
  EXPECT_TRUE(reg.removed<Health>().empty());
}

TEST(Registry, ViewVisitsExactlyEntitiesWithAllComponents) {
  engine::Registry reg;
  std::vector<engine::Entity> both;
  for (int i = 0; i < 10; ++i) {
    const engine::Entity e = reg.create();
    if (i % 2 == 0) reg.emplace<Health>(e, Health{i});
    if (i % 3 == 0) reg.emplace<engine::Name>(e, engine::Name{std::to_string(i)});
    if (i % 2 == 0 && i % 3 == 0) both.push_back(e);
  }
  std::vector<engine::Entity> seen;
  reg.view<Health, engine::Name>().each([&](engine::Entity e, const Health& h, const engine::Name& n) {
    EXPECT_EQ(std::to_string(h.hp), n.value);
    seen.push_back(e);
  });
  std::sort(seen.begin(), seen.end(), [](auto a, auto b) { return a.index < b.index; });
  EXPECT_EQ(seen, both);
  EXPECT_TRUE((reg.view<Health, engine::Camera>().entities().empty()));
}

TEST(Registry, WriteMarksChangedUntilNextFrame) {
  engine::Registry reg;
  const engine::Entity a = reg.create();
  const engine::Entity b = reg.create();
  reg.emplace<Health>(a);
  reg.emplace<Health>(b);
  reg.begin_frame();
  EXPECT_TRUE(reg.changed<Health>().empty());
  EXPECT_EQ(reg.get<Health>(a).hp, 100);  // reads do not mark
  EXPECT_FALSE(reg.changed<Health>(a));
  reg.write<Health>(b).hp = 3;
  reg.write<Health>(b).hp = 4;  // twice: listed once
  ASSERT_EQ(reg.changed<Health>().size(), 1u);
  EXPECT_EQ(reg.changed<Health>()[0], b);
  EXPECT_TRUE(reg.changed<Health>(b));
  reg.begin_frame();
  EXPECT_FALSE(reg.changed<Health>(b));
  EXPECT_EQ(reg.get<Health>(b).hp, 4);
}

TEST(Registry, RemoveKeepsOtherComponentsIntact) {
  engine::Registry reg;
  std::vector<engine::Entity> es;
  for (int i = 0; i < 5; ++i) {
    es.push_back(reg.create());
    reg.emplace<Health>(es.back(), Health{i});
  }
  reg.remove<Health>(es[1]);  // swap-and-pop must keep the moved entity's data
  for (int i = 0; i < 5; ++i) {
    if (i == 1) {
      EXPECT_FALSE(reg.has<Health>(es[1]));
    } else {
      EXPECT_EQ(reg.get<Health>(es[static_cast<size_t>(i)]).hp, i);
    }
  }
}

TEST(RegistryDeathTest, GetOfMissingComponentNamesTheContract) {
  engine::Registry reg;
  const engine::Entity a = reg.create();
  reg.emplace<Health>(reg.create());
  EXPECT_DEATH((void)reg.get<Health>(a), "entity has no component of this type");
  reg.destroy(a);
  EXPECT_DEATH(reg.destroy(a), "destroy\\(\\) of an invalid entity");
}

}  // namespace
