// The logical agent's order journal (no DDS): what is stored comes back in arrival order with
// how far each order got, ended orders are bounded, and bad files are refused with the file
// named.

#include <sqlite3.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "agents/logical_agent/src/order_journal.hpp"

namespace drover::logical_agent {
namespace {

namespace fs = std::filesystem;

class OrderJournalTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("drover-order-journal-" + std::to_string(::getpid()) + "-" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path file(const std::string& name = "V1.db") const { return dir_ / name; }

  static Order order(const std::string& name, std::vector<std::string> locations = {"left-4", "right-4"}) {
    Order out;
    out.name = name;
    for (const auto& location : locations) {
      out.destinations.push_back(Destination{topology::kNoEntity, location, "load", {{"pallet", "p-" + name}}});
    }
    out.properties = {{"priority", "high"}};
    out.created = 1000;
    return out;
  }

  static std::vector<std::string> names(const std::vector<Order>& orders) {
    std::vector<std::string> out;
    for (const auto& o : orders) out.push_back(o.name + ":" + to_string(o.state));
    return out;
  }

  /// Runs `sql` on the file directly (another program, or damage).
  void poke(const fs::path& path, const std::string& sql) {
    sqlite3* db = nullptr;
    ASSERT_EQ(sqlite3_open(path.c_str(), &db), SQLITE_OK);
    char* message = nullptr;
    const int rc = sqlite3_exec(db, sql.c_str(), nullptr, nullptr, &message);
    const std::string error = message ? message : "";
    sqlite3_free(message);
    sqlite3_close(db);
    ASSERT_EQ(rc, SQLITE_OK) << error;
  }

  fs::path dir_;
};

TEST_F(OrderJournalTest, WhatIsStoredComesBackInArrivalOrderWithHowFarEachOrderGot) {
  {
    auto journal = OrderJournal::open(file(), "V1");
    ASSERT_TRUE(journal) << journal.error().message;
    auto a = order("a");
    auto b = order("b", {"left-0"});
    auto c = order("c");
    ASSERT_TRUE(journal->add(a));
    ASSERT_TRUE(journal->add(b));
    ASSERT_TRUE(journal->add(c));
    a.state = OrderState::running;
    a.started = 2000;
    a.destination = 1;
    a.action_command = "1700000000-7";
    a.withdrawal = "line stopped";
    ASSERT_TRUE(journal->update(a));
    b.state = OrderState::failed;
    b.finished = 3000;
    b.failure = "stalled too long";
    ASSERT_TRUE(journal->update(b));
  }
  // Another life of the agent.
  auto journal = OrderJournal::open(file(), "V1");
  ASSERT_TRUE(journal) << journal.error().message;
  const auto loaded = journal->load();
  ASSERT_TRUE(loaded) << loaded.error().message;
  ASSERT_EQ(names(*loaded), (std::vector<std::string>{"a:running", "b:failed", "c:queued"}));
  const Order& a = (*loaded)[0];
  EXPECT_EQ(a.destination, 1u);
  EXPECT_EQ(a.started, 2000);
  EXPECT_FALSE(a.finished);
  EXPECT_EQ(a.created, 1000);
  EXPECT_EQ(a.action_command, "1700000000-7");
  EXPECT_EQ(a.withdrawal, "line stopped");
  ASSERT_EQ(a.destinations.size(), 2u);
  EXPECT_EQ(a.destinations[1].location_id, "right-4");
  EXPECT_EQ(a.destinations[1].location, topology::kNoEntity) << "resolved by the agent against its topology";
  EXPECT_EQ(a.destinations[1].operation, "load");
  EXPECT_EQ(a.destinations[1].properties.at("pallet"), "p-a");
  EXPECT_EQ(a.properties.at("priority"), "high");
  const Order& b = (*loaded)[1];
  EXPECT_EQ(b.finished, 3000);
  EXPECT_EQ(b.failure, "stalled too long");
  EXPECT_FALSE(b.action_command);
  EXPECT_FALSE((*loaded)[2].started);
}

TEST_F(OrderJournalTest, KeepsTheNewestEndedOrdersAndAForgottenNameComesBackLast) {
  auto journal = OrderJournal::open(file(), "V1", 2);
  ASSERT_TRUE(journal) << journal.error().message;
  std::vector<Order> orders;
  for (const char* name : {"a", "b", "c", "d", "e"}) {
    orders.push_back(order(name));
    ASSERT_TRUE(journal->add(orders.back()));
  }
  for (std::size_t i : {0u, 1u, 3u, 2u}) {  // d ends before c
    orders[i].state = OrderState::finished;
    ASSERT_TRUE(journal->update(orders[i]));
  }
  // Four ended, two kept: the two newest by arrival (c and d); e still queued.
  auto loaded = journal->load();
  ASSERT_TRUE(loaded) << loaded.error().message;
  EXPECT_EQ(names(*loaded), (std::vector<std::string>{"c:finished", "d:finished", "e:queued"}));
  // "c" forgotten by the agent and sent again: stored as the newest, not in its old place.
  ASSERT_TRUE(journal->add(order("c")));
  loaded = journal->load();
  ASSERT_TRUE(loaded) << loaded.error().message;
  EXPECT_EQ(names(*loaded), (std::vector<std::string>{"d:finished", "e:queued", "c:queued"}));
}

TEST_F(OrderJournalTest, AnOrderWithTextThatIsNotUtf8IsRefusedAndTheJournalGoesOn) {
  auto journal = OrderJournal::open(file(), "V1");
  ASSERT_TRUE(journal) << journal.error().message;
  auto bad = order("bad");
  bad.destinations[0].properties["pallet"] = "p-\xff";  // DDS strings carry any bytes
  const auto refused = journal->add(bad);
  ASSERT_FALSE(refused);
  EXPECT_EQ(refused.error().code, ErrorCode::invalid_argument);
  EXPECT_NE(refused.error().message.find("order 'bad' cannot be stored"), std::string::npos)
      << refused.error().message;
  // Nothing of it stored, and no transaction left open.
  ASSERT_TRUE(journal->add(order("good")));
  const auto loaded = journal->load();
  ASSERT_TRUE(loaded) << loaded.error().message;
  EXPECT_EQ(names(*loaded), (std::vector<std::string>{"good:queued"}));
}

TEST_F(OrderJournalTest, AnotherVehiclesJournalAnotherKindOfFileAndOneInUseAreRefusedNamingTheFile) {
  {
    auto journal = OrderJournal::open(file(), "V1");
    ASSERT_TRUE(journal) << journal.error().message;
    ASSERT_TRUE(journal->add(order("a")));
    // A second process (or agent) on the same file.
    auto second = OrderJournal::open(file(), "V1");
    ASSERT_FALSE(second);
    EXPECT_EQ(second.error().code, ErrorCode::unavailable);
    EXPECT_NE(second.error().message.find("in use by another process"), std::string::npos) << second.error().message;
  }
  auto other = OrderJournal::open(file(), "V2");
  ASSERT_FALSE(other);
  EXPECT_EQ(other.error().code, ErrorCode::conflict);
  EXPECT_NE(other.error().message.find(file().string()), std::string::npos) << other.error().message;
  EXPECT_NE(other.error().message.find("vehicle 'V1'"), std::string::npos) << other.error().message;

  // A topology agent's journal: the same frame, another owner row.
  ASSERT_NO_FATAL_FAILURE(poke(file("topology.db"),
                               "CREATE TABLE schema_version (version INTEGER NOT NULL) STRICT;"
                               "CREATE TABLE meta (key TEXT PRIMARY KEY, value ANY NOT NULL) STRICT;"
                               "INSERT INTO schema_version VALUES (1);"
                               "INSERT INTO meta VALUES ('topology_key', 'topology ''h'' (all partitions)');"));
  auto topology = OrderJournal::open(file("topology.db"), "V1");
  ASSERT_FALSE(topology);
  EXPECT_EQ(topology.error().code, ErrorCode::parse);
  EXPECT_NE(topology.error().message.find("not a Drover order journal"), std::string::npos) << topology.error().message;

  std::ofstream(file("text.db")) << "a topology file, perhaps, but no database\n";
  auto text = OrderJournal::open(file("text.db"), "V1");
  ASSERT_FALSE(text);
  EXPECT_EQ(text.error().code, ErrorCode::parse) << text.error().message;
  EXPECT_NE(text.error().message.find("text.db"), std::string::npos) << text.error().message;

  auto nowhere = OrderJournal::open(dir_ / "missing-dir" / "V1.db", "V1");
  ASSERT_FALSE(nowhere);
  EXPECT_EQ(nowhere.error().code, ErrorCode::io);
  EXPECT_NE(nowhere.error().message.find("directory does not exist"), std::string::npos) << nowhere.error().message;
}

TEST_F(OrderJournalTest, AnOperatorsPauseOutlivesTheAgentUntilItIsResumed) {
  {
    auto journal = OrderJournal::open(file(), "V1");
    ASSERT_TRUE(journal) << journal.error().message;
    EXPECT_EQ(journal->load_pause().value(), std::nullopt) << "a new journal is not paused";
    ASSERT_TRUE(journal->store_pause("aisle 4 blocked"));
    ASSERT_TRUE(journal->store_pause("aisle 4 cleaned"));  // paused again: the newer reason
  }
  {
    auto journal = OrderJournal::open(file(), "V1");
    ASSERT_TRUE(journal) << journal.error().message;
    EXPECT_EQ(journal->load_pause().value(), std::optional<std::string>("aisle 4 cleaned"));
    ASSERT_TRUE(journal->store_pause(std::nullopt));
    ASSERT_TRUE(journal->store_pause(std::nullopt)) << "resuming twice is no error";
  }
  {
    auto journal = OrderJournal::open(file(), "V1");
    ASSERT_TRUE(journal) << journal.error().message;
    EXPECT_EQ(journal->load_pause().value(), std::nullopt);
  }
  ASSERT_NO_FATAL_FAILURE(poke(file(), "INSERT INTO meta (key, value) VALUES ('paused', 42)"));
  auto journal = OrderJournal::open(file(), "V1");
  ASSERT_TRUE(journal) << journal.error().message;
  const auto damaged = journal->load_pause();
  ASSERT_FALSE(damaged);
  EXPECT_EQ(damaged.error().code, ErrorCode::parse);
  EXPECT_NE(damaged.error().message.find("table meta, row 'paused': the reason is not text"), std::string::npos)
      << damaged.error().message;
  EXPECT_NE(damaged.error().message.find(file().string()), std::string::npos) << damaged.error().message;
}

TEST_F(OrderJournalTest, ADamagedRowIsRefusedNamingTableRowAndColumn) {
  {
    auto journal = OrderJournal::open(file(), "V1");
    ASSERT_TRUE(journal) << journal.error().message;
    ASSERT_TRUE(journal->add(order("a")));
    ASSERT_TRUE(journal->add(order("b")));
  }
  const auto load_error = [&]() -> std::string {
    auto journal = OrderJournal::open(file(), "V1");
    if (!journal) return "open: " + journal.error().message;
    auto loaded = journal->load();
    return loaded ? std::string("loaded") : loaded.error().message;
  };
  ASSERT_NO_FATAL_FAILURE(poke(file(), "UPDATE orders SET state = 'flying' WHERE name = 'b'"));
  EXPECT_NE(load_error().find("table orders row 2: column state is not an order state ('flying')"), std::string::npos)
      << load_error();
  ASSERT_NO_FATAL_FAILURE(poke(file(), "UPDATE orders SET state = 'running'"));
  EXPECT_NE(load_error().find("row 2: column state is 'running' for a second order"), std::string::npos)
      << load_error();
  ASSERT_NO_FATAL_FAILURE(poke(file(), "UPDATE orders SET state = 'queued', destinations = '{}' WHERE name = 'a'"));
  EXPECT_NE(load_error().find("row 1: column destinations is not a list of destinations"), std::string::npos)
      << load_error();
  ASSERT_NO_FATAL_FAILURE(poke(file(),
                               "UPDATE orders SET destinations = '[{\"location\": \"x\", \"operation\": \"NOP\", "
                               "\"properties\": {}}]', destination = 1 WHERE name = 'a'"));
  EXPECT_NE(load_error().find("row 1: column destination is out of range (1 of 1 destinations)"), std::string::npos)
      << load_error();
  // A name no order may have (a key on the wire, bounded there): before, the agent stopped
  // with "Not enough memory in the buffer stream" when it first published the order.
  ASSERT_NO_FATAL_FAILURE(poke(file(), "UPDATE orders SET destination = 0, name = '" + std::string(300, 'o') +
                                           "' WHERE name = 'a'"));
  EXPECT_NE(load_error().find("row 1: column name is not a valid order name: order name 'ooo"), std::string::npos)
      << load_error();
  EXPECT_NE(load_error().find("is 300 bytes long, at most 255 are allowed"), std::string::npos) << load_error();
}

}  // namespace
}  // namespace drover::logical_agent
