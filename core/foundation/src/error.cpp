#include <dicestack/core/error.hpp>

#include <algorithm>
#include <cctype>

namespace dicestack {
namespace {

constexpr std::size_t kWordHead = 120;  // bytes kept from a long word's start
constexpr std::size_t kWordTail = 40;   // and from its end

bool is_continuation(char c) { return (static_cast<unsigned char>(c) & 0xC0) == 0x80; }

// The word `word` cut to its head and tail, each moved to a character boundary.
std::string cut_word(const std::string& word) {
  std::size_t head = kWordHead;
  while (head > 0 && is_continuation(word[head])) --head;
  std::size_t tail = word.size() - kWordTail;
  while (tail < word.size() && is_continuation(word[tail])) ++tail;
  std::size_t cut = 0;  // characters, not bytes: each starts with a byte that does not continue one
  for (std::size_t i = head; i < tail; ++i) cut += is_continuation(word[i]) ? 0 : 1;
  return word.substr(0, head) + "...[" + std::to_string(cut) + " characters cut]..." + word.substr(tail);
}

}  // namespace

std::string readable_message(const std::string& message, std::size_t longest) {
  longest = std::max(longest, kWordHead + kWordTail);
  std::string out;
  std::size_t at = 0;
  while (at < message.size()) {
    const bool space = std::isspace(static_cast<unsigned char>(message[at])) != 0;
    std::size_t end = at;
    while (end < message.size() && (std::isspace(static_cast<unsigned char>(message[end])) != 0) == space) ++end;
    const std::string word = message.substr(at, end - at);
    out += !space && word.size() > longest ? cut_word(word) : word;
    at = end;
  }
  return out;
}

}  // namespace dicestack
